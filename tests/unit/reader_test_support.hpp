// Test helpers shared by the reader tests: a binary builder and an "it fails like this" check.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <utility>

#include "core/error.hpp"

namespace levelset::test {

// Succeeds when read() throws levelset::Error with exactly this code and where, and a reason.
// describe(result) says what a read that should have failed returned.
template <typename Read, typename Describe>
::testing::AssertionResult fails_with(Read&& read, Describe&& describe, ErrorCode code,
                                      std::string_view where) {
  try {
    const auto r = read();
    return ::testing::AssertionFailure() << "read succeeded (" << describe(r) << "); expected "
                                         << to_string(code) << " at " << where;
  } catch (const Error& e) {
    if (e.code() != code || e.where() != where || e.reason().empty())
      return ::testing::AssertionFailure()
             << "got '" << e.what() << "'; expected " << to_string(code) << " at " << where;
    return ::testing::AssertionSuccess() << e.what();
  }
}

// Visits every seed of a fuzz corpus directory under LEVELSET_FUZZ_CORPUS: the first byte of a
// seed picks the extension from `extensions` (as the fuzz targets do), the rest is the file.
// visit(bytes, name) must read it successfully. Returns the number of seeds seen.
template <std::size_t N, typename Visit>
int for_each_fuzz_seed(const char* corpus, const char* const (&extensions)[N], Visit&& visit) {
  const std::filesystem::path dir = std::filesystem::path(LEVELSET_FUZZ_CORPUS) / corpus;
  EXPECT_TRUE(std::filesystem::is_directory(dir)) << dir;
  if (!std::filesystem::is_directory(dir)) return 0;
  int seen = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_FALSE(bytes.empty()) << entry.path();
    if (bytes.empty()) continue;
    // Seeds are small valid files; "bomb_*" and "bad_*" seeds are hostile ones the readers must
    // refuse (visit checks how), and bombs may be larger.
    const std::string stem = entry.path().stem().string();
    EXPECT_LT(bytes.size(), stem.rfind("bomb_", 0) == 0 ? 131072u : 4096u) << entry.path();
    const std::string name = entry.path().stem().string() + extensions[static_cast<unsigned char>(bytes[0]) % N];
    EXPECT_NO_THROW(visit(std::string_view(bytes).substr(1), name)) << entry.path();
    ++seen;
  }
  return seen;
}

// Little/big-endian binary builder for PLY and STL inputs.
struct Bytes {
  std::string s;
  bool big = false;

  Bytes& text(std::string_view t) {
    s += t;
    return *this;
  }
  template <typename T>
  Bytes& put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big == (std::endian::native == std::endian::little))
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    s.append(raw, sizeof(T));
    return *this;
  }
};

}  // namespace levelset::test
