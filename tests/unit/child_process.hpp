// run_child: runs a program in a child process and reports how it ended and what it cost, for
// tests that hold a real binary (levelsetd) to a memory and time bound ("resource bombs").
//
// argv[0] is the program's path (no PATH search); stdin is /dev/null; stdout and stderr are
// captured whole. The child is killed (SIGKILL) once it has run timeout_s seconds; then
// signaled is true and timed_out says why. peak_rss_kb is the child's own maximum resident
// set (wait4's rusage, kilobytes): unlike getrusage(RUSAGE_CHILDREN) it is not the maximum
// over every child this process has waited for. A program that cannot be started gives
// exit_code 127 and the reason in stderr_text, as a shell would.
// Threading: one call at a time per process is the simple rule (it waits for its own pid only,
// so concurrent calls work too).
#pragma once

#include <string>
#include <vector>

namespace levelset::test {

struct ChildResult {
  int exit_code = -1;         // exit status, or -1 when signaled
  bool signaled = false;      // killed by a signal (term_signal), including the timeout's SIGKILL
  int term_signal = 0;
  bool timed_out = false;
  std::string stdout_text, stderr_text;
  long peak_rss_kb = 0;       // ru_maxrss of the child
  double seconds = 0;         // wall time from spawn to exit
};

ChildResult run_child(std::vector<std::string> argv, double timeout_s);

// The levelsetd this build made (LEVELSET_LEVELSETD, set by tests/CMakeLists.txt).
std::string levelsetd_path();

}  // namespace levelset::test
