// Fuzz target: whole job files (jobs/job.hpp): the text is parsed and, when it parses, run
// end to end by run_job as the daemon would (inputs confined to an empty folder, so only
// built-in shapes and CGAL's sample data resolve; outputs to a scratch folder). The seeds are
// small jobs of every application; a watchdog cancels each run after kCancelAfter, so a
// mutation that asks for a huge grid or many steps must end through the progress hooks with
// Error{Cancelled} (the replay driver calls any input over 2 s a hang). Only levelset::Error
// may leave run_job.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

#include <unistd.h>

#include "config/config_file.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"
#include "jobs/job.hpp"

namespace {

constexpr auto kCancelAfter = std::chrono::milliseconds(250);

// Scratch folders, made once per process and removed at its exit: an empty base (inputs) and
// the outputs.
struct Scratch {
  std::filesystem::path dir;
  Scratch() : dir(std::filesystem::temp_directory_path() / ("levelset_fuzz_job_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir / "in");
    std::filesystem::create_directories(dir / "out");
  }
  ~Scratch() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
};

const std::filesystem::path& scratch() {
  static const Scratch s;
  return s.dir;
}

// Cancels `token` after kCancelAfter unless stopped first.
class Watchdog {
 public:
  explicit Watchdog(std::shared_ptr<levelset::CancelToken> token)
      : thread_([this, token] {
          std::unique_lock<std::mutex> lock(mutex_);
          if (!cv_.wait_for(lock, kCancelAfter, [this] { return done_; })) token->cancel();
        }) {}
  ~Watchdog() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  levelset::config::ParseOptions parse;
  parse.limits.max_bytes = 1 << 14;
  parse.limits.max_entries = 512;
  levelset::config::Set root;
  try {
    root = levelset::config::parse_config(text, parse);
  } catch (const levelset::Error&) {
    return 0;
  }
  levelset::jobs::JobOptions options;
  options.base_dir = (scratch() / "in").string();
  options.output_dir = (scratch() / "out").string();
  options.name = "fuzz.conf";
  options.confine_inputs = true;
  auto token = std::make_shared<levelset::CancelToken>();
  options.progress.cancel = token;
  try {
    Watchdog watchdog(token);
    levelset::jobs::run_job(root, options);
  } catch (const levelset::Error&) {
  }
  return 0;
}
