#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/progress.hpp"

namespace levelset {

TEST(Error, MessageNamesCodePlaceAndReason) {
  const Error e(ErrorCode::Truncated, at_byte("a.lsg", 4096), "payload ends early");
  EXPECT_EQ(e.code(), ErrorCode::Truncated);
  EXPECT_EQ(e.where(), "a.lsg @ byte 4096");
  EXPECT_EQ(e.reason(), "payload ends early");
  EXPECT_STREQ(e.what(), "truncated at a.lsg @ byte 4096: payload ends early");
  EXPECT_EQ(Error(ErrorCode::ParseError, at_line("m.off", 12), "x").where(), "m.off:12");
}

TEST(Error, EveryCodeHasADistinctName) {
  const ErrorCode all[] = {ErrorCode::InvalidArgument, ErrorCode::IoError, ErrorCode::ParseError,
                           ErrorCode::Truncated, ErrorCode::Corrupt, ErrorCode::UnsupportedVersion,
                           ErrorCode::UnsupportedFormat, ErrorCode::LimitExceeded,
                           ErrorCode::NonFinite, ErrorCode::Cancelled};
  for (std::size_t i = 0; i < std::size(all); ++i)
    for (std::size_t j = i + 1; j < std::size(all); ++j) EXPECT_NE(to_string(all[i]), to_string(all[j]));
}

TEST(ProgressHook, ReportsAndCancels) {
  auto token = std::make_shared<CancelToken>();
  ProgressHook hook;
  int calls = 0;
  double last = -1;
  hook.on_progress = [&](double f, std::string_view) { ++calls; last = f; };
  hook.cancel = token;
  hook.step(0.5, "half");
  EXPECT_EQ(calls, 1);
  EXPECT_DOUBLE_EQ(last, 0.5);
  token->cancel();
  try {
    hook.step(0.75, "late");
    FAIL() << "cancelled hook did not throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
    EXPECT_EQ(e.where(), "late");
  }
  EXPECT_EQ(calls, 1);
}

}  // namespace levelset
