// LocalDaemon: the embedded default. With no --server the window starts its own
// `levelsetd serve --port 0`, reads the URL from its "levelsetd listening on URL" line and stops
// it on exit (SIGTERM, then SIGKILL after a deadline; always reaped: no process is left). The
// child also gets SIGTERM when this process dies (PR_SET_PDEATHSIG), so a crash leaves nothing.
// Start it before any GL context or thread exists: it forks.
#pragma once

#include <sys/types.h>

#include <string>

namespace levelset::gui {

// levelsetd beside this executable (same folder, or ../../server/ in a build tree), else on PATH;
// "" when none is found.
std::string find_levelsetd(const std::string& self_exe);
// $XDG_STATE_HOME/levelset-gui/daemon.log (~/.local/state/... without it); its folder is made.
std::string default_daemon_log();

class LocalDaemon {
 public:
  // Throws std::runtime_error naming the binary and what it printed when it does not start in
  // `timeout` seconds. Its log (stderr: a line per request) goes to `log_file` (truncated; ""
  // or unwritable: this process's stderr).
  LocalDaemon(const std::string& binary, const std::string& data_dir, const std::string& log_file,
              double timeout = 30);
  ~LocalDaemon();
  LocalDaemon(const LocalDaemon&) = delete;
  LocalDaemon& operator=(const LocalDaemon&) = delete;

  const std::string& url() const { return url_; }
  pid_t pid() const { return pid_; }
  void stop(double timeout = 15);

 private:
  pid_t pid_ = -1;
  int out_fd_ = -1;
  std::string url_;
};

}  // namespace levelset::gui
