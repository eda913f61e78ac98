// Replay driver for the fuzz targets when no libFuzzer is available (gcc builds, ctest).
//
// Usage: <target> CORPUS_DIR [--mutations N] [--seed S]
// Runs LLVMFuzzerTestOneInput on every file in CORPUS_DIR (sorted by name), then on N
// deterministic mutations of them (std::mt19937_64 seeded with S, default 1): bit flips,
// interesting bytes and digits, truncation, chunk duplication and deletion, insertion of huge
// or hostile numbers, splices of two seeds.
// Prints "<N> inputs, 0 crashes" and returns 0. Returns 1 (after printing the input, escaped
// and truncated) when an exception escapes the target (the targets catch levelset::Error, so
// anything escaping is a bug) or one input takes longer than 2 s in two runs in a row (a slow
// path; a watchdog thread reports a hang, 5 s, and exits even if the input never finishes).
// A crash (signal) prints which input was running and the input, then dies with the signal.
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <string_view>
#include <thread>
#include <typeinfo>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

constexpr double kMaxSecondsPerInput = 2.0;
constexpr std::size_t kMaxInputBytes = 1 << 16;

// The input being run, for the signal handler and the watchdog.
const std::string* g_current = nullptr;
std::uint64_t g_current_index = 0;
std::atomic<std::int64_t> g_started_ns{0};  // steady clock at the start of the input; 0: idle
std::atomic<bool> g_finished{false};

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string escaped(std::string_view bytes, std::size_t limit = 300) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < limit; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\\') {
      out += "\\\\";
    } else if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  if (bytes.size() > limit) out += "... (" + std::to_string(bytes.size()) + " bytes)";
  return out;
}

void write_all(const char* s, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(2, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<std::size_t>(w);
  }
}

void on_signal(int sig) {
  // Only async-signal-safe calls: format by hand.
  char number[32];
  std::size_t len = 0;
  std::uint64_t v = g_current_index;
  do {
    number[len++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  write_all("\nCRASH (signal) in input #", 26);
  for (std::size_t i = 0; i < len; ++i) write_all(&number[len - 1 - i], 1);
  write_all(", first bytes in hex:\n", 23);
  if (g_current != nullptr) {
    static constexpr char kHex[] = "0123456789abcdef";
    const std::size_t n = std::min<std::size_t>(g_current->size(), 512);
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = static_cast<unsigned char>((*g_current)[i]);
      const char pair[2] = {kHex[c >> 4], kHex[c & 15]};
      write_all(pair, 2);
    }
    write_all("\n", 1);
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

class Mutator {
 public:
  Mutator(const std::vector<std::string>& seeds, std::uint64_t seed) : seeds_(seeds), rng_(seed) {}

  std::string next() {
    std::string s = seeds_[pick(seeds_.size())];
    const std::size_t rounds = 1 + pick(4);
    for (std::size_t r = 0; r < rounds; ++r) mutate(s);
    if (s.size() > kMaxInputBytes) s.resize(kMaxInputBytes);
    return s;
  }

 private:
  std::size_t pick(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng_() % n); }

  void mutate(std::string& s) {
    static constexpr std::string_view kTokens[] = {"99999999999999",
                                                   "-1",
                                                   "nan",
                                                   "inf",
                                                   "-inf",
                                                   "1e308",
                                                   "1e999",
                                                   "4294967295",
                                                   "4294967296",
                                                   "2147483648",
                                                   "-2147483648",
                                                   "18446744073709551615",
                                                   "99999999999999999999999",
                                                   "0",
                                                   "3",
                                                   "\n",
                                                   " ",
                                                   "#",
                                                   "/",
                                                   "-",
                                                   ".",
                                                   "+",
                                                   "1e-400",
                                                   "end_header\n",
                                                   "element vertex 1000000000000\n",
                                                   "property list uchar int x\n",
                                                   "facet normal 0 0 0\n",
                                                   "f -1 -2 -3\n",
                                                   "v 1 2 3\n"};
    static constexpr char kBytes[] = {'\0', '\xff', '\x7f', '\x80', '\n', '\r', ' ', '#',
                                      '-',  '0',    '1',    '9',    '.',  'e',  '/', '\t'};
    switch (pick(9)) {
      case 0:  // bit flip
        if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1u << pick(8));
        break;
      case 1:  // interesting byte
        if (!s.empty()) s[pick(s.size())] = kBytes[pick(sizeof kBytes)];
        break;
      case 2:  // random digit
        if (!s.empty()) s[pick(s.size())] = static_cast<char>('0' + pick(10));
        break;
      case 3:  // truncation
        s.resize(pick(s.size() + 1));
        break;
      case 4: {  // duplicate a chunk
        if (s.empty()) break;
        const std::size_t at = pick(s.size());
        const std::size_t len = 1 + pick(std::min<std::size_t>(s.size() - at, 256));
        const std::string chunk = s.substr(at, len);
        s.insert(pick(s.size() + 1), chunk);
        break;
      }
      case 5: {  // delete a chunk
        if (s.empty()) break;
        const std::size_t at = pick(s.size());
        s.erase(at, 1 + pick(std::min<std::size_t>(s.size() - at, 64)));
        break;
      }
      case 6: {  // insert a hostile token
        const std::string_view tok = kTokens[pick(std::size(kTokens))];
        s.insert(pick(s.size() + 1), tok);
        break;
      }
      case 7: {  // replace a number-like run with a hostile token
        if (s.empty()) break;
        std::size_t at = pick(s.size());
        std::size_t end = at;
        while (end < s.size() &&
               (std::isdigit(static_cast<unsigned char>(s[end])) || s[end] == '.' || s[end] == '-'))
          ++end;
        const std::string_view tok = kTokens[pick(14)];
        s.replace(at, end - at, tok);
        break;
      }
      default: {  // splice with another seed (keeps the format byte of this one)
        const std::string& other = seeds_[pick(seeds_.size())];
        if (other.empty() || s.empty()) break;
        const std::size_t cut = pick(s.size());
        s = s.substr(0, cut) + other.substr(pick(other.size()));
        break;
      }
    }
  }

  const std::vector<std::string>& seeds_;
  std::mt19937_64 rng_;
};

// Runs one input once: its wall-clock seconds, or a negative value (after printing why) when an
// exception escaped.
double timed_run(const std::string& input, std::uint64_t index, std::string_view label) {
  g_current = &input;
  g_current_index = index;
  const auto start = std::chrono::steady_clock::now();
  g_started_ns.store(now_ns());
  try {
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(input.data()), input.size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "FAIL: input #%llu (%.*s) threw %s: %s\ninput: %s\n",
                 static_cast<unsigned long long>(index), static_cast<int>(label.size()),
                 label.data(), typeid(e).name(), e.what(), escaped(input).c_str());
    return -1.0;
  } catch (...) {
    std::fprintf(stderr, "FAIL: input #%llu (%.*s) threw a non-std exception\ninput: %s\n",
                 static_cast<unsigned long long>(index), static_cast<int>(label.size()),
                 label.data(), escaped(input).c_str());
    return -1.0;
  }
  g_started_ns.store(0);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Runs one input; false (after printing why) on an escaped exception or a hang. An input over
// the time limit runs once more and fails only when that run is over it as well: a hang or a
// slow path repeats, a moment of load on a shared machine (the 2-core CI running tests side by
// side) does not (fuzz_job once took 2.02 s there with both cores busy).
bool run_one(const std::string& input, std::uint64_t index, std::string_view label) {
  const double first = timed_run(input, index, label);
  if (first < 0.0) return false;
  if (first <= kMaxSecondsPerInput) return true;
  const double again = timed_run(input, index, label);
  if (again < 0.0) return false;
  if (again > kMaxSecondsPerInput) {
    std::fprintf(stderr, "FAIL: input #%llu (%.*s) took %.2f s and %.2f s (limit %.1f s)\ninput: %s\n",
                 static_cast<unsigned long long>(index), static_cast<int>(label.size()),
                 label.data(), first, again, kMaxSecondsPerInput, escaped(input).c_str());
    return false;
  }
  return true;
}

// Reports an input that runs far past the limit (one that may never return) and exits.
void watchdog() {
  const std::int64_t limit_ns = static_cast<std::int64_t>(kMaxSecondsPerInput * 2.5e9);
  while (!g_finished.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const std::int64_t started = g_started_ns.load();
    if (started != 0 && now_ns() - started > limit_ns && g_current != nullptr) {
      std::fprintf(stderr, "FAIL: input #%llu hangs (running for more than %.1f s)\ninput: %s\n",
                   static_cast<unsigned long long>(g_current_index), limit_ns / 1e9,
                   escaped(*g_current).c_str());
      std::fflush(stderr);
      std::_Exit(1);
    }
  }
}

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s CORPUS_DIR [--mutations N] [--seed S]\n", argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage(argv[0]);
  const std::filesystem::path corpus = argv[1];
  std::uint64_t mutations = 0;
  std::uint64_t seed = 1;
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if ((arg == "--mutations" || arg == "--seed") && i + 1 < argc) {
      char* end = nullptr;
      const unsigned long long value = std::strtoull(argv[++i], &end, 10);
      if (end == argv[i] || *end != '\0') return usage(argv[0]);
      (arg == "--mutations" ? mutations : seed) = value;
    } else {
      return usage(argv[0]);
    }
  }
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(corpus, ec))
    if (entry.is_regular_file()) files.push_back(entry.path());
  if (ec || files.empty()) {
    std::fprintf(stderr, "no seed files in %s\n", corpus.c_str());
    return 2;
  }
  std::sort(files.begin(), files.end());
  std::vector<std::string> seeds;
  for (const auto& file : files) {
    std::ifstream in(file, std::ios::binary);
    seeds.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  std::signal(SIGSEGV, on_signal);
  std::signal(SIGABRT, on_signal);
  std::signal(SIGILL, on_signal);
  std::signal(SIGFPE, on_signal);
  std::signal(SIGBUS, on_signal);

  std::thread guard(watchdog);
  const auto run_all = [&]() -> std::uint64_t {
    std::uint64_t index = 0;
    for (std::size_t i = 0; i < seeds.size(); ++i)
      if (!run_one(seeds[i], index++, files[i].filename().string())) return 0;
    Mutator mutator(seeds, seed);
    for (std::uint64_t m = 0; m < mutations; ++m) {
      const std::string input = mutator.next();
      if (!run_one(input, index++, "mutation")) return 0;
    }
    return index;
  };
  const std::uint64_t index = run_all();
  g_finished.store(true);
  guard.join();
  if (index == 0) return 1;
  std::printf("%llu inputs, 0 crashes\n", static_cast<unsigned long long>(index));
  return 0;
}
