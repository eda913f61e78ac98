// ProgressView: a job's progress on stderr. On a terminal, one bar redrawn in place
// ("[#########           ]  45%  evolve  step 120  eta 3 s"); otherwise plain lines
// ("progress: 45% evolve step 120"), one when the stage changes or the fraction moved by 5%.
// finish() ends the bar's line. Threading: one thread.
#pragma once

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

namespace levelset::client {

class ProgressView {
 public:
  enum class Mode { Auto, Bar, Lines, Off };
  explicit ProgressView(Mode mode = Mode::Auto, std::FILE* out = stderr);
  ~ProgressView() { finish(); }

  void update(const nlohmann::json& progress);
  // Prints a line above the bar (log lines while a bar is drawn).
  void message(const std::string& line, std::FILE* stream);
  void finish();

 private:
  std::string describe(const nlohmann::json& progress, int percent) const;
  Mode mode_;
  std::FILE* out_;
  bool bar_drawn_ = false;
  int last_percent_ = -100;
  std::string last_stage_;
};

}  // namespace levelset::client
