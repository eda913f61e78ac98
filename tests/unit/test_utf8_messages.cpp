// Every error message is valid UTF-8 (issue 13): they go into JSON bodies. Each parser that
// quotes its input is fed non-ASCII text and bytes that are not UTF-8 where it quotes them;
// the message must be valid UTF-8 and, where a whole character is quoted, name all of it.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "config/config_file.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "formula/formula.hpp"
#include "grid/lsg_file.hpp"
#include "io/image_reader.hpp"
#include "io/mesh_reader.hpp"
#include "io/point_cloud_reader.hpp"

namespace levelset {

namespace {

const std::string kE = "\xC3\xA9";            // é, U+00E9
const std::string kMinus = "\xE2\x88\x92";    // −, U+2212
const std::string kBad = "\xFF\xFE";          // not UTF-8 at all
const std::string kCut = "\xC3";              // the first half of é
const std::string kSurrogate = "\xED\xA0\x80";  // U+D800 encoded: not a character

// The message of the Error `run` throws ("" and a failure when it throws none).
std::string message_of(const std::function<void()>& run) {
  try {
    run();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

void expect_valid(const std::string& message, const std::string& what) {
  EXPECT_TRUE(is_valid_utf8(message)) << what << ": " << message;
  EXPECT_FALSE(message.empty()) << what;
}

}  // namespace

TEST(Utf8, ValidatorAcceptsCharactersAndRejectsMalformedSequences) {
  EXPECT_TRUE(is_valid_utf8("plain"));
  EXPECT_TRUE(is_valid_utf8(kE + kMinus + "\xF0\x9F\x98\x80"));  // 2, 3 and 4 bytes
  for (const std::string& bad : {kBad, kCut, kSurrogate, std::string("\xC0\xAF"), std::string("\xE0\x80\xAF"),
                                 std::string("\xF4\x90\x80\x80"), std::string("\x80"), "a" + kCut + "b"})
    EXPECT_FALSE(is_valid_utf8(bad)) << sanitize_utf8(bad);
  EXPECT_EQ(sanitize_utf8("a" + kBad + kE), "a\\xFF\\xFE" + kE);
  EXPECT_EQ(sanitize_utf8(kE), kE);
  EXPECT_EQ(utf8_column("a" + kE + "b", 3), 3u);  // 'b' is the third character
}

TEST(Utf8, QuotedCharactersAreWhole) {
  const QuotedCharacter e = quote_character(kE + "+1", 0);
  EXPECT_EQ(e.text, "'" + kE + "' (U+00E9)");
  EXPECT_EQ(e.bytes, 2u);
  EXPECT_EQ(quote_character(kBad, 0).text, "byte 0xFF");
  EXPECT_EQ(quote_character("\t", 0).text, "U+0009");
  EXPECT_EQ(quote_character("x", 0).text, "'x'");
}

TEST(Utf8, ErrorsKeepPlaceAndReasonValid) {
  const Error e(ErrorCode::ParseError, "file" + kBad + ".off:3", "found '" + kCut + "'");
  expect_valid(e.what(), "Error");
  expect_valid(e.where(), "where");
  expect_valid(e.reason(), "reason");
  EXPECT_NE(std::string(e.what()).find("\\xFF"), std::string::npos) << e.what();
}

TEST(Utf8, FormulaErrorsNameTheWholeCharacter) {
  const std::string m = message_of([] { formula::compile(kE + "+1"); });
  expect_valid(m, "formula");
  EXPECT_NE(m.find("'" + kE + "' (U+00E9)"), std::string::npos) << m;
  const std::string minus = message_of([] { formula::compile("1 " + kMinus + " H"); });
  expect_valid(minus, "formula minus");
  EXPECT_NE(minus.find("U+2212"), std::string::npos) << minus;
  EXPECT_NE(minus.find("write '-'"), std::string::npos) << minus;
  EXPECT_NE(minus.find("column 3"), std::string::npos) << minus;
  for (const std::string& bytes : {kBad, kCut, kSurrogate, "H*" + kCut, "foo" + kE + "(1)"}) {
    const std::string msg = message_of([&] { formula::compile(bytes); });
    expect_valid(msg, "formula " + sanitize_utf8(bytes));
  }
}

TEST(Utf8, ConfigErrorsAreValid) {
  for (const std::string& text :
       {"job = evolve\n" + kE + " = 1\n", "job = evolve\n" + kBad + " = 1\n", "job" + kCut + " = evolve\n",
        "evolve { speed = 1 }\n}" + kE, "input { shape = " + kBad + " \n", kSurrogate + "\n"}) {
    const std::string m = message_of([&] { config::parse_config(text); });
    expect_valid(m, "config " + sanitize_utf8(text));
  }
  const std::string m = message_of([] { config::parse_config("job = evolve\n" + kE + " = 1\n"); });
  EXPECT_NE(m.find(kE), std::string::npos) << m;
  config::Set root = config::parse_config("job = evolve\n");
  expect_valid(message_of([&] { config::set_override(root, "a" + kBad); }), "--set");
  expect_valid(message_of([&] { config::set_override(root, kCut + "=1"); }), "--set key");
}

TEST(Utf8, ReaderErrorsAreValid) {
  struct Case {
    const char* name;
    std::string bytes;
    std::function<void(const std::string&, const std::string&)> read;
  };
  auto mesh = [](const std::string& bytes, const std::string& name) { read_mesh_from_memory(bytes, name); };
  auto cloud = [](const std::string& bytes, const std::string& name) { read_point_cloud_from_memory(bytes, name); };
  auto image = [](const std::string& bytes, const std::string& name) { read_image_from_memory(bytes, name); };
  auto lsg = [](const std::string& bytes, const std::string& name) { decode_lsg(bytes, name); };
  const std::vector<Case> cases = {
      {"x.off", "OFF\n3 1 0\n0 0 0\n1 " + kE + " 0\n0 1 0\n3 0 1 2\n", mesh},
      {"x.off", kBad + "OFF\n", mesh},
      {"x.obj", "v 0 0 " + kBad + "\nf 1 2 3\n", mesh},
      {"x.obj", kE + " 1 2 3\n", mesh},
      {"x.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float " + kE + "\nend_header\n", mesh},
      {"x.ply", "ply\nformat " + kBad + " 1.0\nend_header\n", mesh},
      {"x.stl", "solid " + kE + "\nfacet normal 0 0 1\nouter loop\nvertex 0 0 " + kCut + "\n", mesh},
      {"x.tria", "3 1\n0 0 0\n" + kBad + "\n", mesh},
      {"x.xyz", "0 0 0\n1 " + kE + " 1\n", cloud},
      {"x.xyzn", "0 0 0 0 0 1\n1 1 1 " + kBad + "\n", cloud},
      {"x.pwn", "2\n0 0 " + kMinus + "1\n", cloud},
      {"x.inr", "#INRIMAGE-4#{\nXDIM=" + kE + "\n", image},
      {"x.nrrd", "NRRD0004\ntype: " + kBad + "\n", image},
      {"x.nrrd", "NRRD0004\n" + kE + ": 3\n", image},
      {"x.lsg", kBad + std::string(64, '\0'), lsg},
  };
  for (const Case& c : cases) {
    const std::string m = message_of([&] { c.read(c.bytes, c.name); });
    expect_valid(m, std::string(c.name) + " " + sanitize_utf8(c.bytes.substr(0, 40)));
  }
  // A file name that is not UTF-8 is quoted in every message about the file.
  const std::string m = message_of([] { read_mesh_from_memory("OFF\n1 1 0\n", "mesh" + kBad + ".off"); });
  expect_valid(m, "file name");
}

}  // namespace levelset
