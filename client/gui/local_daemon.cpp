#include "local_daemon.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>
#include <vector>

namespace levelset::gui {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string find_levelsetd(const std::string& self_exe) {
  std::error_code ec;
  const fs::path dir = fs::canonical(self_exe, ec).parent_path();
  for (const fs::path& p : {dir / "levelsetd", dir / ".." / ".." / "server" / "levelsetd"})
    if (::access(p.c_str(), X_OK) == 0) return fs::weakly_canonical(p, ec).string();
  const char* path = std::getenv("PATH");
  std::string list = path != nullptr ? path : "";
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t colon = std::min(list.find(':', start), list.size());
    const fs::path p = fs::path(list.substr(start, colon - start)) / "levelsetd";
    if (colon > start && ::access(p.c_str(), X_OK) == 0) return p.string();
    start = colon + 1;
  }
  return "";
}

std::string default_daemon_log() {
  const char* xdg = std::getenv("XDG_STATE_HOME");
  const char* home = std::getenv("HOME");
  const fs::path base = xdg != nullptr && *xdg != '\0' ? fs::path(xdg) : fs::path(home != nullptr ? home : ".") / ".local" / "state";
  std::error_code ec;
  fs::create_directories(base / "levelset-gui", ec);
  return (base / "levelset-gui" / "daemon.log").string();
}

namespace {

// The child: its own stdout to the pipe, stderr to the log, dies with its parent.
[[noreturn]] void exec_child(const std::string& binary, const std::string& data_dir, int pipe_write, int log_fd,
                             pid_t parent) {
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (::getppid() != parent) ::_exit(127);  // the parent died before prctl
  ::dup2(pipe_write, STDOUT_FILENO);
  if (log_fd >= 0) ::dup2(log_fd, STDERR_FILENO);
  std::vector<std::string> args = {binary, "serve", "--port", "0"};
  if (!data_dir.empty()) args.insert(args.end(), {"--data", data_dir});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(binary.c_str(), argv.data());
  ::_exit(127);
}

}  // namespace

LocalDaemon::LocalDaemon(const std::string& binary, const std::string& data_dir, const std::string& log_file,
                         double timeout) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  const int log_fd = log_file.empty() ? -1 : ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) exec_child(binary, data_dir, fds[1], log_fd, parent);
  ::close(fds[1]);
  if (log_fd >= 0) ::close(log_fd);
  out_fd_ = fds[0];
  std::string line;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout);
  while (Clock::now() < deadline) {
    pollfd p{out_fd_, POLLIN, 0};
    const int left = int(std::chrono::duration<double, std::milli>(deadline - Clock::now()).count());
    if (::poll(&p, 1, std::max(1, left)) <= 0) continue;
    char c = 0;
    if (::read(out_fd_, &c, 1) != 1) break;  // it exited
    if (c == '\n') break;
    line += c;
  }
  const std::string prefix = "levelsetd listening on ";
  if (line.rfind(prefix, 0) != 0) {
    stop(5);
    throw std::runtime_error(binary + " serve did not start" + (line.empty() ? "" : ": " + line) +
                             (log_file.empty() ? "" : " (its log: " + log_file + ")"));
  }
  url_ = line.substr(prefix.size());
}

LocalDaemon::~LocalDaemon() { stop(); }

void LocalDaemon::stop(double timeout) {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    const auto deadline = Clock::now() + std::chrono::duration<double>(timeout);
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
      if (Clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pid_ = -1;
  }
  if (out_fd_ >= 0) ::close(out_fd_);
  out_fd_ = -1;
}

}  // namespace levelset::gui
