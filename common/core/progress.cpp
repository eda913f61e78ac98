#include "core/progress.hpp"

#include <string>

#include "core/error.hpp"

namespace levelset {

void ProgressHook::check(std::string_view stage) const {
  if (cancelled()) throw Error(ErrorCode::Cancelled, std::string(stage), "operation cancelled");
}

void ProgressHook::step(double fraction, std::string_view stage) const {
  check(stage);
  if (on_progress) {
    std::lock_guard<std::mutex> lock(*mutex_);
    on_progress(fraction, stage);
  }
}

}  // namespace levelset
