// ServiceConfig: every setting of `levelsetd serve`, from one table (service_options()) that
// drives the config file (configs/server.conf, the project's format, top-level keys), the
// environment (LEVELSET_<KEY>), the flags (--key-with-dashes) and `serve --help`, so the three
// sources can never disagree on a name. Precedence: defaults < file < environment < flags.
// Sizes take K, M, G, T suffixes (powers of 1024); durations are seconds.
// Errors: Error{InvalidArgument} naming the source ("LEVELSET_PORT", "server.conf:3:8",
//   "--port") and the reason.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace levelset::service {

struct ServiceConfig {
  std::string host = "127.0.0.1";
  int port = 8080;
  std::string data_dir;  // default: $XDG_STATE_HOME/levelset, else ~/.local/state/levelset
  std::string token_file;
  std::string tokens;    // "TOKEN[:ro],..." (LEVELSET_TOKENS)
  bool insecure_no_auth = false;
  std::string tls_cert, tls_key;
  std::string cors_origin;
  std::string log_format = "text";  // text | json
  std::string replica;              // prefix of every id (a StatefulSet pod name); default: host name
  std::string render = "egl";       // egl | osmesa | off: the offscreen GL context for frames
  std::string peers;                // "replica=URL,...": the other replicas (session-affine routing)
  // Limits (0 = sized from the machine at start: see finalize()).
  int max_jobs = 0;                 // jobs running at once (default: one per two cores)
  int max_queued_jobs = 64;
  int max_sessions = 256;
  std::uint64_t max_session_voxels = std::uint64_t{1} << 28;
  std::uint64_t max_band_memory = 0;       // all sessions' bands (default: half the memory)
  std::uint64_t max_upload_bytes = std::uint64_t{1} << 30;
  std::uint64_t max_uploads_total = std::uint64_t{8} << 30;
  std::uint64_t max_body_bytes = std::uint64_t{4} << 20;  // JSON bodies
  int max_formula_length = 4096;
  int max_streams = 64;             // open SSE / MJPEG streams
  int stream_fps = 15;              // MJPEG parts per second at most
  double checkpoint_seconds = 30;
  double shutdown_deadline = 10;
  double read_timeout = 30;         // against slow senders
};

struct ServiceOption {
  std::string key;   // config file key; flag --key-with-dashes; env LEVELSET_KEY
  std::string help;
  std::function<void(ServiceConfig&, const std::string& value)> set;
  std::function<std::string(const ServiceConfig&)> get;
};

const std::vector<ServiceOption>& service_options();

std::string env_name(const std::string& key);   // "max_jobs" -> "LEVELSET_MAX_JOBS"
std::string flag_name(const std::string& key);  // "max_jobs" -> "--max-jobs"

// Applies a config file (Error at FILE:LINE:COL), then every LEVELSET_* variable present.
void apply_config_file(ServiceConfig& config, const std::string& path);
void apply_environment(ServiceConfig& config);
// Fills the machine-sized defaults (max_jobs, max_band_memory, data_dir, replica) and checks
// the whole (a port in range, limits > 0): Error{InvalidArgument}.
void finalize(ServiceConfig& config);

}  // namespace levelset::service
