// The configuration / job file reader against the thesis's own sample (appendix A.3) and
// every error kind, with places.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "config/config_file.hpp"
#include "core/error.hpp"

namespace levelset::config {

namespace {

const char* kThesisSample = R"(// triangle mesh file to load by default
tmfile = duck
// point cloud file to load by default
pcfile = knot

// raster resolution
raster {
  // number of samples is 2 ^ (3*depth)
  depth = 6
}

// default PDE formula
PDE {
  // mean-gaussian-curvature flow
  formula = -sign(H)*sqrt(K+abs(K))
}

// renderer options
renderer {
  // width and hight of the renderer window
  windowsize = 512
  // initial rotation matrices of the object and the light
  rotateobj = (.9,.1,-.4,0,0,.9,.4,0,.5,-.4,0.8,0,0,0,0,1)
  rotatelight = (1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1)
}

// files section
files {
  // identifier used in the program
  bunny {
    // type of the file
    type = off
    // relative path to the file
    file = ./data/bunny.off
    // bounding box of the object
    bbmin = (-0.12,0.01,-0.08)
    bbmax = (0.08,0.2,0.07)
  }
}
)";

// The error's place and reason, or empty strings when nothing was thrown.
struct Failure {
  ErrorCode code{};
  std::string where, reason;
  bool thrown = false;
};
Failure parse_failure(std::string_view text, ParseOptions options = {}) {
  options.name = "job.conf";
  try {
    (void)parse_config(text, options);
  } catch (const Error& e) {
    return {e.code(), e.where(), e.reason(), true};
  }
  return {};
}

}  // namespace

TEST(ConfigFile, ReadsTheThesisSample) {
  const Set root = parse_config(kThesisSample);
  ASSERT_EQ(root.entries.size(), 6u);
  const Entry* tm = root.find("tmfile");
  ASSERT_NE(tm, nullptr);
  EXPECT_EQ(tm->value.kind, Value::Kind::Word);
  EXPECT_EQ(tm->value.text, "duck");
  EXPECT_EQ(tm->line, 2);
  EXPECT_EQ(tm->column, 1);
  const Entry* depth = root.find("raster")->set.find("depth");
  ASSERT_NE(depth, nullptr);
  EXPECT_EQ(depth->value.kind, Value::Kind::Number);
  EXPECT_EQ(depth->value.number, 6.0);
  EXPECT_EQ(depth->line, 9);
  EXPECT_EQ(depth->column, 3);
  const Entry* formula = root.find("PDE")->set.find("formula");
  EXPECT_EQ(formula->value.kind, Value::Kind::Text);
  EXPECT_EQ(formula->value.text, "-sign(H)*sqrt(K+abs(K))");
  const Entry* rot = root.find("renderer")->set.find("rotateobj");
  EXPECT_EQ(rot->value.kind, Value::Kind::Tuple);
  ASSERT_EQ(rot->value.tuple.size(), 16u);
  EXPECT_DOUBLE_EQ(rot->value.tuple[2], -0.4);
  EXPECT_DOUBLE_EQ(rot->value.tuple[15], 1.0);
  const Set& bunny = root.find("files")->set.find("bunny")->set;
  EXPECT_EQ(bunny.find("file")->value.text, "./data/bunny.off");
  EXPECT_EQ(bunny.find("file")->value.kind, Value::Kind::Word);
  EXPECT_EQ(bunny.find("bbmin")->value.tuple, (std::vector<double>{-0.12, 0.01, -0.08}));
}

TEST(ConfigFile, StringsCommentsAndSetsOnOneLine) {
  const Set root = parse_config("a = \"say \\\"hi\\\" // not a comment\"  // a comment\n"
                                "job { speed = 1 - eps*H  // trailing\n eps = 0.1 }\n"
                                "n = -2.5e-3\nw = sphere_1\n");
  EXPECT_EQ(root.find("a")->value.kind, Value::Kind::String);
  EXPECT_EQ(root.find("a")->value.text, "say \"hi\" // not a comment");
  const Set& job = root.find("job")->set;
  EXPECT_EQ(job.find("speed")->value.text, "1 - eps*H");
  EXPECT_EQ(job.find("eps")->value.number, 0.1);
  EXPECT_EQ(root.find("n")->value.number, -2.5e-3);
  EXPECT_EQ(root.find("w")->value.kind, Value::Kind::Word);
  EXPECT_TRUE(parse_config("").entries.empty());
  EXPECT_TRUE(parse_config("// only a comment\n\n").entries.empty());
}

TEST(ConfigFile, EntriesShareALineSeparatedByBlanks) {
  // The README's example (issue 14: refused before), and every value kind followed by another
  // entry on its line.
  const Set root = parse_config(
      "raster { resolution = 128  band = 3 }\n"
      "output { mesh = ply  lsg = yes  method = mc }\n"
      "a = \"s\" b = (1, 2) c = word d { e = 1 } f = 2\n"
      "pde { formula = -(k1+k2) * 0.5  eps = 0.1 }\n"
      "g = x == y\n");
  const Set& raster = root.find("raster")->set;
  EXPECT_EQ(raster.find("resolution")->value.number, 128);
  EXPECT_EQ(raster.find("band")->value.number, 3);
  EXPECT_EQ(root.find("output")->set.find("method")->value.text, "mc");
  EXPECT_EQ(root.find("a")->value.text, "s");
  EXPECT_EQ(root.find("b")->value.tuple, (std::vector<double>{1, 2}));
  EXPECT_EQ(root.find("c")->value.kind, Value::Kind::Word);
  EXPECT_EQ(root.find("d")->set.find("e")->value.number, 1);
  EXPECT_EQ(root.find("f")->value.number, 2);
  // A formula keeps its blanks and operators; only "KEY =" after a blank starts an entry, and
  // '==' does not.
  EXPECT_EQ(root.find("pde")->set.find("formula")->value.text, "-(k1+k2) * 0.5");
  EXPECT_EQ(root.find("pde")->set.find("eps")->value.number, 0.1);
  EXPECT_EQ(root.find("g")->value.text, "x == y");
}

TEST(ConfigFile, ByteOrderMarkIsSkipped) {
  const Set root = parse_config("\xEF\xBB\xBF" "job = offset\nraster { band = 3 }\n");
  EXPECT_EQ(root.find("job")->value.text, "offset");
  // Places count from after the mark.
  const Failure f = parse_failure("\xEF\xBB\xBF" "a = 1\nb 2\n");
  ASSERT_TRUE(f.thrown);
  EXPECT_EQ(f.where, "job.conf:2:3");
  // A mark anywhere else is a character like any other: refused where a key is expected.
  EXPECT_TRUE(parse_failure("a = 1\n\xEF\xBB\xBF" "b = 2\n").thrown);
}

TEST(ConfigFile, ErrorsNameLineAndColumn) {
  struct Case {
    const char* text;
    const char* where;
    const char* says;
  };
  const Case cases[] = {
      {"a = 1\nb 2\n", "job.conf:2:3", "expected '=' or '{'"},
      {"a = (1, 2\n", "job.conf:1:10", "unterminated tuple"},
      {"a = (1, x, 3)\n", "job.conf:1:9", "expected a number in the tuple"},
      {"a = 1\na = 2\n", "job.conf:2:1", "duplicate key 'a'"},
      {"s {\n  a = 1\n", "job.conf:1:1", "not closed"},
      {"a = 1\n}\n", "job.conf:2:1", "'}' without its set"},
      {"a = \"open\n", "job.conf:1:10", "unterminated string"},
      {"a = \"bad \\q\"\n", "job.conf:1:10", "unknown escape"},
      {"1a = 2\n", "job.conf:1:1", "expected a key"},
      {"a =\n", "job.conf:1:4", "expected a value"},
      {"a = \"x\" y\n", "job.conf:1:9", "after the value"},
  };
  for (const Case& c : cases) {
    const Failure f = parse_failure(c.text);
    ASSERT_TRUE(f.thrown) << c.text;
    EXPECT_EQ(f.code, ErrorCode::ParseError) << c.text;
    EXPECT_EQ(f.where, c.where) << c.text << " -> " << f.reason;
    EXPECT_NE(f.reason.find(c.says), std::string::npos) << c.text << " -> " << f.reason;
  }
}

TEST(ConfigFile, LimitsAreTypedErrors) {
  ParseOptions small;
  small.limits.max_bytes = 10;
  EXPECT_EQ(parse_failure("a = 12345678901\n", small).code, ErrorCode::LimitExceeded);
  std::string deep;
  for (int i = 0; i < 100; ++i) deep += "s {\n";
  const Failure d = parse_failure(deep);
  ASSERT_TRUE(d.thrown);
  EXPECT_NE(d.reason.find("nested deeper"), std::string::npos) << d.reason;
  ParseOptions few;
  few.limits.max_entries = 3;
  EXPECT_EQ(parse_failure("a=1\nb=2\nc=3\nd=4\n", few).code, ErrorCode::LimitExceeded);
  std::string many = "t = (";
  for (int i = 0; i < 5000; ++i) many += "1,";
  many += "1)\n";
  EXPECT_EQ(parse_failure(many).code, ErrorCode::ParseError);
  // A large flat file parses in one pass (places are counted forward).
  std::string big;
  for (int i = 0; i < 20000; ++i) {
    const std::string n = std::to_string(i);
    big.append("k").append(n).append(" = ").append(n).append("\n");
  }
  const Set root = parse_config(big);
  EXPECT_EQ(root.entries.size(), 20000u);
  EXPECT_EQ(root.entries.back().line, 20000);
}

TEST(ConfigFile, UnknownKeysSuggestTheNearestKnownOne) {
  const Set root = parse_config("raster {\n  dept = 6\n}\n");
  check_keys(root, {"raster", "PDE"}, "job.conf");
  try {
    check_keys(root.find("raster")->set, {"depth", "resolution"}, "job.conf");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    EXPECT_EQ(e.where(), "job.conf:2:3");
    EXPECT_NE(e.reason().find("did you mean 'depth'"), std::string::npos) << e.reason();
  }
  try {
    check_keys(parse_config("zzzz = 1\n"), {"depth"}, "job.conf");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.reason().find("did you mean"), std::string::npos) << e.reason();
  }
}

TEST(ConfigFile, OverridesFromTheCommandLine) {
  Set root = parse_config(kThesisSample);
  set_override(root, "raster.depth=7");
  EXPECT_EQ(root.find("raster")->set.find("depth")->value.number, 7.0);
  set_override(root, "PDE.formula = 1 - eps*H");
  EXPECT_EQ(root.find("PDE")->set.find("formula")->value.text, "1 - eps*H");
  set_override(root, "new.inner.t=(1,2,3)");
  EXPECT_EQ(root.find("new")->set.find("inner")->set.find("t")->value.tuple, (std::vector<double>{1, 2, 3}));
  EXPECT_THROW(set_override(root, "raster=3"), Error);        // a set, not a value
  EXPECT_THROW(set_override(root, "tmfile.x=3"), Error);      // a value, not a set
  EXPECT_THROW(set_override(root, "no equals sign"), Error);
  EXPECT_THROW(set_override(root, "a..b=1"), Error);
  EXPECT_THROW(set_override(root, "a=(1,"), Error);
}

TEST(ConfigFile, FilesNameThemselvesInErrors) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "levelset_config_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "bad.conf").string();
  {
    FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fputs("a = 1\nb = (\n", f);
    std::fclose(f);
  }
  try {
    (void)read_config_file(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), path + ":2:6");
  }
  EXPECT_THROW((void)read_config_file((dir / "missing.conf").string()), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace levelset::config
