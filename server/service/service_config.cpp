#include "service/service_config.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <thread>

#include "config/config_file.hpp"
#include "core/error.hpp"
#include "core/text.hpp"

namespace levelset::service {

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  throw Error(ErrorCode::InvalidArgument, key, why);
}

std::uint64_t parse_size(const std::string& key, const std::string& v) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  std::string unit(end);
  for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (!unit.empty() && unit.back() == 'B') unit.pop_back();
  if (!unit.empty() && unit.back() == 'I') unit.pop_back();
  double scale = 1;
  if (unit == "K") scale = 1024.0;
  else if (unit == "M") scale = 1024.0 * 1024;
  else if (unit == "G") scale = 1024.0 * 1024 * 1024;
  else if (unit == "T") scale = 1024.0 * 1024 * 1024 * 1024;
  else if (!unit.empty() || end == v.c_str()) bad(key, "expected a size such as 512M or 4G, found '" + sanitize_utf8(v.substr(0, 40)) + "'");
  if (!(std::isfinite(x) && x >= 0 && x * scale < 1.8e19)) bad(key, "expected a size >= 0, found '" + sanitize_utf8(v.substr(0, 40)) + "'");
  return static_cast<std::uint64_t>(x * scale);
}

long long parse_int(const std::string& key, const std::string& v, long long lo, long long hi) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != 0 || !(x == std::floor(x)) || x < double(lo) || x > double(hi))
    bad(key, "expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) + ", found '" +
                 sanitize_utf8(v.substr(0, 40)) + "'");
  return static_cast<long long>(x);
}

double parse_seconds(const std::string& key, const std::string& v) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != 0 || !(std::isfinite(x) && x >= 0 && x <= 1e7))
    bad(key, "expected seconds >= 0, found '" + sanitize_utf8(v.substr(0, 40)) + "'");
  return x;
}

bool parse_bool(const std::string& key, const std::string& v) {
  if (v == "yes" || v == "true" || v == "1" || v == "on") return true;
  if (v == "no" || v == "false" || v == "0" || v == "off") return false;
  bad(key, "expected yes or no, found '" + sanitize_utf8(v.substr(0, 40)) + "'");
}

template <typename Field>
ServiceOption text(std::string key, std::string help, Field field) {
  return {key, std::move(help), [field](ServiceConfig& c, const std::string& v) { c.*field = v; },
          [field](const ServiceConfig& c) { return c.*field; }};
}
template <typename Field>
ServiceOption size(std::string key, std::string help, Field field) {
  return {key, std::move(help), [key, field](ServiceConfig& c, const std::string& v) { c.*field = parse_size(key, v); },
          [field](const ServiceConfig& c) { return std::to_string(c.*field); }};
}
template <typename Field>
ServiceOption integer(std::string key, std::string help, Field field, long long lo, long long hi) {
  return {key, std::move(help),
          [key, field, lo, hi](ServiceConfig& c, const std::string& v) { c.*field = int(parse_int(key, v, lo, hi)); },
          [field](const ServiceConfig& c) { return std::to_string(c.*field); }};
}
template <typename Field>
ServiceOption seconds(std::string key, std::string help, Field field) {
  return {key, std::move(help), [key, field](ServiceConfig& c, const std::string& v) { c.*field = parse_seconds(key, v); },
          [field](const ServiceConfig& c) { return format_number(c.*field); }};
}

}  // namespace

const std::vector<ServiceOption>& service_options() {
  static const std::vector<ServiceOption> options = {
      text("host", "Address to listen on (127.0.0.1; beyond loopback requires tokens)", &ServiceConfig::host),
      integer("port", "TCP port (0: a free one, printed when ready)", &ServiceConfig::port, 0, 65535),
      text("data", "Data directory: sessions, uploads, the job journal", &ServiceConfig::data_dir),
      text("token_file", "File of bearer tokens, one per line: TOKEN [rw|ro]", &ServiceConfig::token_file),
      text("tokens", "Bearer tokens, comma-separated TOKEN[:ro]", &ServiceConfig::tokens),
      {"insecure_no_auth", "Listen beyond loopback without tokens (never in production)",
       [](ServiceConfig& c, const std::string& v) { c.insecure_no_auth = parse_bool("insecure_no_auth", v); },
       [](const ServiceConfig& c) { return std::string(c.insecure_no_auth ? "yes" : "no"); }},
      text("tls_cert", "TLS certificate (PEM); with tls_key serves HTTPS", &ServiceConfig::tls_cert),
      text("tls_key", "TLS private key (PEM)", &ServiceConfig::tls_key),
      text("cors_origin", "Allow browser requests from this origin (off when empty)", &ServiceConfig::cors_origin),
      {"log_format", "Log lines: text or json",
       [](ServiceConfig& c, const std::string& v) {
         if (v != "text" && v != "json") bad("log_format", "expected text or json, found '" + sanitize_utf8(v.substr(0, 40)) + "'");
         c.log_format = v;
       },
       [](const ServiceConfig& c) { return c.log_format; }},
      text("replica", "Prefix of every session and job id (default: the host name)", &ServiceConfig::replica),
      {"render", "Offscreen rendering for frames and streams: egl, osmesa or off",
       [](ServiceConfig& c, const std::string& v) {
         if (v != "egl" && v != "osmesa" && v != "off")
           bad("render", "expected egl, osmesa or off, found '" + sanitize_utf8(v.substr(0, 40)) + "'");
         c.render = v;
       },
       [](const ServiceConfig& c) { return c.render; }},
      text("peers",
           "The other replicas as REPLICA=URL,...: requests for their sessions and jobs are redirected there, and "
           "GET /api/v1/sessions lists theirs too",
           &ServiceConfig::peers),
      integer("max_jobs", "Jobs running at once (0: one per two cores)", &ServiceConfig::max_jobs, 0, 1024),
      integer("max_queued_jobs", "Jobs waiting; beyond it 429", &ServiceConfig::max_queued_jobs, 0, 100000),
      integer("max_sessions", "Sessions held; beyond it 507", &ServiceConfig::max_sessions, 1, 1000000),
      size("max_session_voxels", "Active voxels one session may hold; beyond it 507", &ServiceConfig::max_session_voxels),
      size("max_band_memory", "Memory of all bands together (0: half the machine's)", &ServiceConfig::max_band_memory),
      size("max_upload_bytes", "Size of one upload; beyond it 413", &ServiceConfig::max_upload_bytes),
      size("max_uploads_total", "All uploads together; beyond it 507", &ServiceConfig::max_uploads_total),
      size("max_body_bytes", "Size of a JSON request body; beyond it 413", &ServiceConfig::max_body_bytes),
      integer("max_formula_length", "Characters in a speed formula", &ServiceConfig::max_formula_length, 16, 1 << 20),
      integer("max_streams", "Open event and frame streams; beyond it 503", &ServiceConfig::max_streams, 1, 4096),
      integer("stream_fps", "MJPEG frames per second at most (a slow client gets the newest, skipping the rest)",
              &ServiceConfig::stream_fps, 1, 120),
      seconds("checkpoint_seconds", "Checkpoint a long job this often", &ServiceConfig::checkpoint_seconds),
      seconds("shutdown_deadline", "On SIGTERM, stop jobs and exit within this time", &ServiceConfig::shutdown_deadline),
      seconds("read_timeout", "Drop a client that sends nothing for this long", &ServiceConfig::read_timeout),
  };
  return options;
}

std::string env_name(const std::string& key) {
  std::string s = "LEVELSET_";
  for (char c : key) s += char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string flag_name(const std::string& key) {
  std::string s = "--";
  for (char c : key) s += c == '_' ? '-' : c;
  return s;
}

void apply_config_file(ServiceConfig& config, const std::string& path) {
  const config::Set set = config::read_config_file(path);
  std::vector<std::string> keys;
  for (const ServiceOption& o : service_options()) keys.push_back(o.key);
  config::check_keys(set, keys, path);
  for (const config::Entry& e : set.entries) {
    if (e.is_set) throw Error(ErrorCode::InvalidArgument, config::place_of(e, path), "'" + e.key + "' takes a value, not a set");
    for (const ServiceOption& o : service_options()) {
      if (o.key != e.key) continue;
      try {
        o.set(config, e.value.text);
      } catch (const Error& err) {
        throw Error(ErrorCode::InvalidArgument, config::place_of(e, path), err.reason());
      }
    }
  }
}

void apply_environment(ServiceConfig& config) {
  for (const ServiceOption& o : service_options()) {
    const std::string name = env_name(o.key);
    const char* v = std::getenv(name.c_str());
    if (v == nullptr) continue;
    try {
      o.set(config, v);
    } catch (const Error& err) {
      throw Error(ErrorCode::InvalidArgument, name, err.reason());
    }
  }
}

void finalize(ServiceConfig& c) {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  if (c.max_jobs == 0) c.max_jobs = int(std::max(1u, cores / 2));
  if (c.max_band_memory == 0) {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    c.max_band_memory = pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) / 2 : std::uint64_t{4} << 30;
  }
  if (c.data_dir.empty()) {
    const char* state = std::getenv("XDG_STATE_HOME");
    const char* home = std::getenv("HOME");
    if (state != nullptr && *state != 0) c.data_dir = std::string(state) + "/levelset";
    else if (home != nullptr && *home != 0) c.data_dir = std::string(home) + "/.local/state/levelset";
    else c.data_dir = "levelset-data";
  }
  if (c.replica.empty()) {
    char name[256] = {};
    c.replica = ::gethostname(name, sizeof name - 1) == 0 && name[0] != 0 ? name : "local";
  }
  for (char& ch : c.replica)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-') ch = '-';
  if (c.replica.size() > 40) c.replica.resize(40);
  if ((c.tls_cert.empty()) != (c.tls_key.empty())) bad("tls_cert", "give both tls_cert and tls_key, or neither");
  if (c.max_session_voxels == 0 || c.max_upload_bytes == 0 || c.max_body_bytes == 0)
    bad("limits", "size limits must be > 0");
}

}  // namespace levelset::service
