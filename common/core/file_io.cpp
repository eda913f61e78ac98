#include "core/file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <utility>

#include "core/error.hpp"
#include "core/huge_pages.hpp"

namespace levelset {

namespace fs = std::filesystem;

namespace {

using Identity = std::pair<dev_t, ino_t>;

std::atomic<bool> g_allow_special{false};
std::atomic<bool> g_guard{false};

// Files this process read and wrote (while the guard is on).
struct Seen {
  std::mutex mutex;
  std::set<Identity> read, written;
};
Seen& seen() {
  static Seen s;
  return s;
}

bool identity_of(const fs::path& path, Identity& id) {
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) return false;
  id = {st.st_dev, st.st_ino};
  return true;
}

// Temp files of writes in progress, for the signal handler: fixed slots of plain chars (a
// handler may not allocate or lock). A write that finds no free slot still works; only its
// cleanup on a signal is lost.
constexpr int kSlots = 64;
constexpr std::size_t kSlotBytes = 4096;
char g_temp_paths[kSlots][kSlotBytes];
std::atomic<int> g_temp_state[kSlots];  // 0 free, 1 being filled, 2 live

int register_temp(const std::string& path) {
  if (path.size() >= kSlotBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_temp_state[i].compare_exchange_strong(expected, 1)) {
      std::memcpy(g_temp_paths[i], path.c_str(), path.size() + 1);
      g_temp_state[i].store(2);
      return i;
    }
  }
  return -1;
}

void release_temp(int slot) {
  if (slot >= 0) g_temp_state[slot].store(0);
}

extern "C" void remove_temps_and_reraise(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_temp_state[i].load() == 2) ::unlink(g_temp_paths[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace
bool is_stdout(const fs::path& path);
namespace {

// The destination's kind, checked before anything is written. Returns true when the path is
// an allowed special file to be written in place.
bool check_destination(const fs::path& path) {
  struct stat st{};
  if (::lstat(path.c_str(), &st) != 0) return false;  // does not exist (or cannot be seen): created
  if (S_ISLNK(st.st_mode)) {
    // /dev/stdout and /proc/self/fd/N are links to a terminal, pipe or socket: with special
    // outputs allowed, such a link is written through in place. A link to anything else (a
    // regular file, a directory, nothing) is never followed nor replaced.
    struct stat target{};
    if (g_allow_special.load() && ::stat(path.c_str(), &target) == 0 &&
        (S_ISCHR(target.st_mode) || S_ISFIFO(target.st_mode) || S_ISSOCK(target.st_mode) || is_stdout(path)))
      return true;
    throw Error(ErrorCode::IoError, path.string(),
                "is a symbolic link; refusing to replace it (write to its target's path instead; a link to a "
                "device, FIFO or stdout is written through only when special outputs are allowed: "
                "levelsetd --allow-special-outputs)");
  }
  if (S_ISREG(st.st_mode)) {
    if (g_guard.load()) {
      Seen& s = seen();
      std::lock_guard lock(s.mutex);
      const Identity id{st.st_dev, st.st_ino};
      if (s.read.count(id))
        throw Error(ErrorCode::IoError, path.string(), "is an input of this run; refusing to overwrite it");
      if (s.written.count(id))
        throw Error(ErrorCode::IoError, path.string(), "was already written by this run (two outputs to one file)");
    }
    return false;
  }
  if (g_allow_special.load() && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode))) return true;
  throw Error(ErrorCode::IoError, path.string(),
              std::string("exists and is not a regular file (") +
                  (S_ISDIR(st.st_mode) ? "a directory" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                                                      : S_ISFIFO(st.st_mode)                            ? "a FIFO"
                                                                                                        : "a special file") +
                  "); refusing to replace it (a device or FIFO is written in place only when special "
                  "outputs are allowed: levelsetd --allow-special-outputs)");
}

void write_all(int fd, const fs::path& path, std::string_view bytes, const char* cleanup) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      if (cleanup) ::unlink(cleanup);
      throw Error(ErrorCode::IoError, path.string(), std::string("write failed: ") + std::strerror(err));
    }
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

bool is_stdout(const fs::path& path) {
  struct stat a{}, b{};
  return ::fstat(1, &b) == 0 && ::stat(path.c_str(), &a) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

void allow_special_outputs(bool on) { g_allow_special.store(on); }
void enable_output_guard(bool on) { g_guard.store(on); }

std::string read_file_bytes(const fs::path& path, std::uint64_t max_bytes) {
  std::error_code ec;
  auto status = fs::status(path, ec);
  if (ec || !fs::exists(status))
    throw Error(ErrorCode::IoError, path.string(), "file does not exist");
  if (!fs::is_regular_file(status))
    throw Error(ErrorCode::IoError, path.string(), "not a regular file");
  const std::uint64_t size = fs::file_size(path, ec);
  if (ec) throw Error(ErrorCode::IoError, path.string(), "cannot stat: " + ec.message());
  if (size > max_bytes)
    throw Error(ErrorCode::LimitExceeded, path.string(),
                "file is " + std::to_string(size) + " bytes, limit is " + std::to_string(max_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::IoError, path.string(), "cannot open for reading");
  if (g_guard.load()) {
    Identity id;
    if (identity_of(path, id)) {
      std::lock_guard lock(seen().mutex);
      seen().read.insert(id);
    }
  }
  std::string bytes;
  resize_with_huge_pages(bytes, size);  // faulted in by one call, not a trap per page
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uint64_t>(in.gcount()) != size)
    throw Error(ErrorCode::IoError, path.string(), "short read");
  return bytes;
}

void write_file_atomically(const fs::path& path, std::string_view bytes) {
  if (check_destination(path)) {
    // An allowed character device or FIFO (or a link to one, checked above): in place.
    // O_APPEND: /dev/stdout redirected to a regular file writes after what is there (nothing
    // after '>', the earlier output after '>>'), never over it.
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd < 0) throw Error(ErrorCode::IoError, path.string(), std::string("cannot open: ") + std::strerror(errno));
    write_all(fd, path, bytes, nullptr);
    ::close(fd);
    return;
  }
  static std::atomic<unsigned> counter{0};
  const fs::path tmp = path.string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter.fetch_add(1));
  const int slot = register_temp(tmp.string());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) {
    const int err = errno;
    release_temp(slot);
    throw Error(ErrorCode::IoError, path.string(), std::string("cannot create temporary file: ") + std::strerror(err));
  }
  try {
    write_all(fd, path, bytes, tmp.c_str());
  } catch (...) {
    release_temp(slot);
    throw;
  }
  auto fail = [&](const char* what) {
    const int err = errno;
    ::unlink(tmp.c_str());
    release_temp(slot);
    throw Error(ErrorCode::IoError, path.string(), std::string(what) + std::strerror(err));
  };
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("flush failed: ");
  }
  if (::close(fd) != 0) fail("flush failed: ");
  // The destination may have changed while we wrote (another process): checked again.
  try {
    check_destination(path);
  } catch (...) {
    ::unlink(tmp.c_str());
    release_temp(slot);
    throw;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("rename failed: ");
  release_temp(slot);
  if (g_guard.load()) {
    Identity id;
    if (identity_of(path, id)) {
      std::lock_guard lock(seen().mutex);
      seen().written.insert(id);
    }
  }
}

void check_output_paths(const std::vector<fs::path>& inputs, const std::vector<fs::path>& outputs) {
  std::set<Identity> input_ids;
  for (const fs::path& in : inputs) {
    Identity id;
    if (identity_of(in, id)) input_ids.insert(id);
  }
  std::set<Identity> output_ids;
  std::set<fs::path> output_paths;
  for (const fs::path& out : outputs) {
    check_destination(out);
    Identity id;
    if (identity_of(out, id)) {
      if (input_ids.count(id)) throw Error(ErrorCode::IoError, out.string(), "is also an input; refusing to overwrite it");
      if (!output_ids.insert(id).second)
        throw Error(ErrorCode::IoError, out.string(), "is named by two outputs; give each output its own file");
    }
    std::error_code ec;
    const fs::path norm = fs::weakly_canonical(fs::absolute(out, ec), ec);
    if (!ec && !output_paths.insert(norm).second)
      throw Error(ErrorCode::IoError, out.string(), "is named by two outputs; give each output its own file");
  }
}

void remove_temp_files_on_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction sa{};
    sa.sa_handler = remove_temps_and_reraise;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    ::sigaction(sig, &sa, nullptr);
  }
}

}  // namespace levelset
