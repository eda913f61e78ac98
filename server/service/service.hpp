// Service: the daemon's state and every operation the API offers, as plain C++ (no HTTP):
// uploads, sessions, jobs, results, metrics. The HTTP layer (server/api) parses requests,
// calls these and writes what they return; errors are ApiError (or the core's Error, mapped
// by ApiError::from_error).
//
// Data directory: sessions/ (session_store.hpp), uploads/ (upload_store.hpp), jobs/<id>.json
// (the journal) and jobs/<id>/ (each job's log, stats and artifacts). On start every session
// comes back and every job the journal shows queued or running becomes interrupted.
// Threading: all members thread-safe; jobs run on the scheduler's workers.
#pragma once

#include <atomic>
#include <chrono>
#include <filesystem>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "service/job_scheduler.hpp"
#include "service/render_service.hpp"
#include "service/service_config.hpp"
#include "service/session_store.hpp"
#include "service/upload_store.hpp"

namespace levelset::service {

struct Reply {
  int status = 200;
  nlohmann::json body;
  std::string location;  // Location header when set
};

struct MeshQuery {
  double iso = 0;
  std::string method = "mc", format = "ply";
};

struct Blob {
  std::shared_ptr<const std::string> bytes;
  std::string etag, content_type, file_name;
};

struct VoxelQuery {
  double min = -1e300, max = 1e300;
  std::vector<std::string> fields{"value"};  // value, closest, curvature (x y z always)
  std::uint64_t offset = 0, limit = 1 << 20;
};

class Service {
 public:
  explicit Service(ServiceConfig config);
  ~Service();

  const ServiceConfig& config() const { return config_; }
  nlohmann::json api_info() const;  // GET /api/v1
  bool ready() const { return ready_.load() && !scheduler_->stopping(); }
  std::string metrics() const;      // Prometheus text
  std::vector<std::string> startup_problems() const { return startup_problems_; }
  // Frames and streams: whether an offscreen GL context renders them, and if not, why (the
  // frame routes answer 503 with it; everything else works).
  bool rendering() const;
  std::string render_status() const;
  // A frame of the session's current state (its preview while a job runs) with its view and
  // the query's settings over it; `state` says which state was drawn (for streams).
  EncodedFrame frame(const std::string& session_id, const FrameRequest& settings, std::uint64_t* state = nullptr);
  RenderService& renderer() { return *render_; }

  UploadStore& uploads() { return *uploads_; }
  SessionStore& sessions() { return *sessions_; }
  JobScheduler& jobs() { return *scheduler_; }

  // Sessions.
  nlohmann::json list_sessions() const;
  Reply create_session(const nlohmann::json& body);  // 201 (primitive, band upload) or 202 (a job)
  // {"name": NEW} renames; {"points": UPLOAD | null} shows a point upload with the session (or
  // stops showing its cloud). Either or both.
  nlohmann::json patch_session(const std::string& id, const nlohmann::json& body);
  // The session's region of influence from its committed band ({}), a snapshot ({"snapshot": SID})
  // or another session's committed band ({"session": ID}).
  nlohmann::json put_roi(const std::string& id, const nlohmann::json& body);
  Reply snapshot(const std::string& id, const nlohmann::json& body);
  nlohmann::json restore(const std::string& id, const std::string& snapshot_id);

  // Jobs.
  Reply submit(const std::string& session_id, const nlohmann::json& body);
  Reply submit_job_file(const nlohmann::json& body);
  nlohmann::json list_jobs() const;
  nlohmann::json cancel(const std::string& job_id);
  nlohmann::json stop(const std::string& job_id);
  Reply resume(const std::string& job_id);
  Blob job_file(const std::string& job_id, const std::string& name);

  // Results (of the committed band, or of the running job's preview).
  Blob mesh(const std::string& session_id, const MeshQuery& query);
  Blob band(const std::string& session_id);
  Blob points(const std::string& session_id);  // the session's point cloud file (404: none)
  Blob roi(const std::string& session_id);     // the session's region of influence as .lsg (404: none)
  Blob voxels(const std::string& session_id, const VoxelQuery& query, std::uint64_t& total, std::string& fields);

  // Idempotency-Key: the first answer to a key is replayed for 24 h (bounded memory).
  std::optional<std::pair<int, std::string>> replay(const std::string& key);
  void remember(const std::string& key, int status, const std::string& body);

  void shutdown(std::chrono::steady_clock::time_point deadline);

  // Counters for /metrics (the HTTP layer counts requests).
  std::atomic<std::uint64_t> requests_total{0}, request_errors_total{0}, streams_open{0};

 private:
  class JobRun;  // service_runner.cpp
  void run_job(Job& job);
  void load_journal();
  std::shared_ptr<Job> make_job(const nlohmann::json& request, const std::string& session_id);
  std::filesystem::path job_dir(const std::string& job_id) const;
  // Keeps a point upload with a session (422 at `place` when the upload is not a point cloud).
  void attach_points(Session& s, const std::string& upload_id, const std::string& place);
  // Grid boxes of bands built from shapes and meshes: 64x the voxels a session may hold, so a
  // request for an absurd resolution is refused before any work, not after minutes of it.
  std::uint64_t domain_budget() const { return config_.max_session_voxels * 64; }

  ServiceConfig config_;
  std::filesystem::path data_;
  std::unique_ptr<SessionStore> sessions_;
  std::unique_ptr<UploadStore> uploads_;
  std::unique_ptr<JobScheduler> scheduler_;
  std::atomic<bool> ready_{false};
  std::vector<std::string> startup_problems_;
  std::unique_ptr<RenderService> render_;
  std::atomic<std::uint64_t> jobs_succeeded_{0}, jobs_failed_{0};

  std::mutex cache_mutex_;
  std::list<std::pair<std::string, Blob>> mesh_cache_;  // most recent first, a few entries
  std::mutex idempotency_mutex_;
  std::map<std::string, std::pair<std::chrono::steady_clock::time_point, std::pair<int, std::string>>> idempotency_;
};

}  // namespace levelset::service
