// Test helpers shared by the reader tests: a binary builder and an "it fails like this" check.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
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
