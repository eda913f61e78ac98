#include "lib/progress_view.hpp"

#include <unistd.h>

#include <cmath>

namespace levelset::client {

using nlohmann::json;

ProgressView::ProgressView(Mode mode, std::FILE* out) : mode_(mode), out_(out) {
  if (mode_ == Mode::Auto) mode_ = ::isatty(::fileno(out_)) ? Mode::Bar : Mode::Lines;
}

std::string ProgressView::describe(const json& p, int percent) const {
  std::string s = std::to_string(percent) + "%";
  const std::string stage = p.value("stage", "");
  if (!stage.empty()) s += " " + stage;
  if (p.contains("step") && p["step"].is_number()) s += " step " + std::to_string(p["step"].get<long long>());
  if (percent < 100 && p.contains("eta_seconds") && p["eta_seconds"].is_number())
    s += " eta " + std::to_string(std::lround(p["eta_seconds"].get<double>())) + " s";
  return s;
}

void ProgressView::update(const json& p) {
  if (mode_ == Mode::Off || !p.is_object()) return;
  double f = p.contains("fraction") && p["fraction"].is_number() ? p["fraction"].get<double>() : 0.0;
  if (!std::isfinite(f)) f = 0;
  f = std::min(1.0, std::max(0.0, f));
  const int percent = int(std::floor(f * 100));
  const std::string stage = p.value("stage", "");
  if (mode_ == Mode::Bar) {
    constexpr int kWidth = 30;
    const int filled = int(std::lround(f * kWidth));
    std::string bar = "\r[" + std::string(std::size_t(filled), '#') + std::string(std::size_t(kWidth - filled), ' ') +
                      "] " + describe(p, percent);
    std::fprintf(out_, "%s\033[K", bar.c_str());
    std::fflush(out_);
    bar_drawn_ = true;
    return;
  }
  if (stage == last_stage_ && percent < last_percent_ + 5 && !(percent == 100 && last_percent_ != 100)) return;
  last_stage_ = stage;
  last_percent_ = percent;
  std::fprintf(out_, "progress: %s\n", describe(p, percent).c_str());
  std::fflush(out_);
}

void ProgressView::message(const std::string& line, std::FILE* stream) {
  if (bar_drawn_) {  // clear the bar's line first
    std::fprintf(out_, "\r\033[K");
    std::fflush(out_);
  }
  std::fprintf(stream, "%s\n", line.c_str());
  std::fflush(stream);
  bar_drawn_ = false;  // redrawn at the next update
}

void ProgressView::finish() {
  if (bar_drawn_) {
    std::fprintf(out_, "\n");
    std::fflush(out_);
    bar_drawn_ = false;
  }
}

}  // namespace levelset::client
