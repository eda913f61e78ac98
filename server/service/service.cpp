#include "service/service.hpp"

#include <thread>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/huge_blocks.hpp"
#include "grid/lsg_file.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"
#include "service/operations.hpp"

#ifndef LEVELSET_VERSION
#define LEVELSET_VERSION "0.0.0"
#endif

namespace levelset::service {

namespace fs = std::filesystem;
using nlohmann::json;

Service::Service(ServiceConfig config) : config_(std::move(config)), data_(config_.data_dir) {
  std::error_code ec;
  fs::create_directories(data_ / "jobs", ec);
  if (ec) throw Error(ErrorCode::IoError, data_.string(), "cannot create the data directory: " + ec.message());
  sessions_ = std::make_unique<SessionStore>(
      data_ / "sessions",
      SessionLimits{config_.max_sessions, config_.max_session_voxels, config_.max_band_memory});
  uploads_ = std::make_unique<UploadStore>(data_ / "uploads", config_.max_upload_bytes, config_.max_uploads_total);
  // Atomic writes cut off by kill -9 leave "<name>.tmp-<pid>-<n>" beside the final name, which
  // is intact: remove them everywhere before loading.
  for (auto it = fs::recursive_directory_iterator(data_, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    if (it->path().filename().string().find(".tmp-") != std::string::npos) fs::remove(it->path(), ec);
  ec.clear();
  startup_problems_ = sessions_->load_all();
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  scheduler_ = std::make_unique<JobScheduler>(config_.max_jobs, config_.max_queued_jobs,
                                              int(std::max(1u, cores / unsigned(config_.max_jobs))),
                                              [this](Job& job) { run_job(job); });
  load_journal();
  render_ = std::make_unique<RenderService>(config_.render, default_renderer_factory());
  ready_ = true;
}

Service::~Service() { shutdown(std::chrono::steady_clock::now()); }

bool Service::rendering() const { return render_->available(); }
std::string Service::render_status() const { return render_->status(); }

EncodedFrame Service::frame(const std::string& session_id, const FrameRequest& settings, std::uint64_t* state) {
  auto s = sessions_->get(session_id);
  FrameRequest r = settings;
  const std::uint64_t serial = s->preview_serial();
  const std::uint64_t cloud = s->points_serial(), roi = s->roi_serial();
  r.band = s->preview();
  r.points = s->points();
  r.roi = s->roi();
  r.view = s->view();
  r.scene_key = session_id + "-v" + std::to_string(s->version()) + "-p" + std::to_string(serial) + "-c" +
                std::to_string(cloud) + "-r" + std::to_string(roi);
  if (state != nullptr) *state = ((serial * 1000003 + s->view_serial()) * 1009 + cloud) * 1013 + roi;  // = frame_state()
  return render_->render(std::move(r), std::chrono::seconds(30));
}

void Service::shutdown(std::chrono::steady_clock::time_point deadline) {
  ready_ = false;
  if (scheduler_) scheduler_->shutdown(deadline);
}

fs::path Service::job_dir(const std::string& job_id) const { return data_ / "jobs" / job_id; }

void Service::load_journal() {
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(data_ / "jobs", ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".json" || !is_valid_id(e.path().stem().string(), 'j')) continue;
    try {
      auto job = Job::from_journal(e.path());
      const JobState s = job->state();
      if (s == JobState::Queued || s == JobState::Running)
        job->set_state(JobState::Interrupted, {{"reason", "the server stopped while the job " +
                                                              std::string(s == JobState::Running ? "ran" : "waited")}});
      job->events().close();
      scheduler_->adopt(job);
    } catch (const Error& err) {
      startup_problems_.push_back(name + ": " + err.what());
    }
  }
}

json Service::api_info() const {
  json ops = json::array();
  for (const OperationInfo& o : operations())
    ops.push_back({{"op", o.name},
                   {"kind", o.kind == OperationInfo::Modifies ? "modifies" : o.kind == OperationInfo::Creates ? "creates" : "reads"},
                   {"stoppable", o.evolution_like},
                   {"summary", o.summary}});
  return {{"name", "levelsetd"},
          {"version", LEVELSET_VERSION},
          {"api", "v1"},
          {"replica", config_.replica},
          {"operations", ops},
          {"upload_formats", {"off", "ply", "obj", "stl", "tria", "xyz", "xyzn", "pwn", "inr", "nrrd", "lsg"}},
          {"limits",
           {{"max_jobs", config_.max_jobs},
            {"max_queued_jobs", config_.max_queued_jobs},
            {"max_sessions", config_.max_sessions},
            {"max_session_voxels", config_.max_session_voxels},
            {"max_band_memory", config_.max_band_memory},
            {"max_upload_bytes", config_.max_upload_bytes},
            {"max_uploads_total", config_.max_uploads_total},
            {"max_body_bytes", config_.max_body_bytes},
            {"max_formula_length", config_.max_formula_length},
            {"max_streams", config_.max_streams}}}};
}

std::string Service::metrics() const {
  std::string out;
  auto metric = [&](const char* name, const char* type, const char* help, double value) {
    out += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n" + name + " " +
           std::to_string(value) + "\n";
  };
  metric("levelset_requests_total", "counter", "HTTP requests answered", double(requests_total.load()));
  metric("levelset_request_errors_total", "counter", "HTTP requests answered with a status >= 400",
         double(request_errors_total.load()));
  metric("levelset_sessions", "gauge", "Sessions held", double(sessions_->count()));
  metric("levelset_band_memory_bytes", "gauge", "Memory of all sessions' bands", double(sessions_->band_memory()));
  metric("levelset_jobs_running", "gauge", "Jobs running", double(scheduler_->running()));
  metric("levelset_jobs_queued", "gauge", "Jobs waiting", double(scheduler_->queued()));
  metric("levelset_jobs_succeeded_total", "counter", "Jobs that succeeded", double(jobs_succeeded_.load()));
  metric("levelset_jobs_failed_total", "counter", "Jobs that failed", double(jobs_failed_.load()));
  metric("levelset_streams_open", "gauge", "Open event streams", double(streams_open.load()));
  metric("levelset_uploads_bytes", "gauge", "Bytes held by uploads", double(uploads_->total_bytes()));
  // The large buffers' pool (core/huge_blocks.hpp): what computations hold, and what freed
  // buffers keep for the next request (at most the keep_freed_memory limit).
  const HugeBlockStats blocks = huge_block_stats();
  metric("levelset_huge_blocks_live_bytes", "gauge", "Bytes of large buffers (1 MiB and more) in use",
         double(blocks.live_bytes));
  metric("levelset_huge_blocks_cached_bytes", "gauge", "Bytes of freed large buffers kept for reuse",
         double(blocks.cached_bytes));
  metric("levelset_huge_blocks_mapped_total", "counter", "Large buffers mapped afresh (not reused)",
         double(blocks.mapped));
  metric("levelset_huge_blocks_reused_total", "counter", "Large buffers served from the kept ones",
         double(blocks.reused + blocks.grown));
  return out;
}

// ---- sessions -------------------------------------------------------------------------------

json Service::list_sessions() const {
  json out = json::array();
  for (const auto& s : sessions_->list()) out.push_back(s->describe());
  return {{"sessions", out}, {"replica", config_.replica}};
}

Reply Service::create_session(const json& body) {
  if (!body.is_object()) throw bad_request("expected a JSON object");
  const std::string name = body.value("name", "");
  if (name.size() > 200) throw unprocessable("body.name", "longer than 200 characters");
  if (body.contains("primitive")) {
    // A built-in shape: the closest thing to `levelsetd primitive`, synchronous (bounded by
    // the raster's limits).
    if (!body["primitive"].is_string()) throw unprocessable("body.primitive", "expected a shape name");
    json request = {{"op", "cpt"}, {"input", {{"shape", body["primitive"]}}}};
    if (body.contains("raster")) request["raster"] = body["raster"];
    OperationContext ctx;
    ctx.request = request;
    ctx.uploads_dir = uploads_->dir();
    ctx.work_dir = data_;
    ctx.max_formula_length = config_.max_formula_length;
    ctx.max_domain_voxels = domain_budget();
    OperationResult r = run_operation(ctx);
    auto s = sessions_->create(config_.replica, name, std::move(*r.band), {{"primitive", body["primitive"]}, {"raster", body.value("raster", json::object())}});
    return {201, s->describe(), "/api/v1/sessions/" + s->id()};
  }
  if (!body.contains("upload") || !body["upload"].is_string())
    throw bad_request("expected \"primitive\": NAME or \"upload\": UPLOAD_ID (and \"name\")");
  const std::string upload = body["upload"].get<std::string>();
  const json meta = uploads_->get(upload);
  const std::string kind = meta.value("kind", "");
  if (kind == "band") {
    NarrowBand band = load_lsg(uploads_->path_of(upload)).band;
    auto s = sessions_->create(config_.replica, name, std::move(band), {{"upload", upload}});
    return {201, s->describe(), "/api/v1/sessions/" + s->id()};
  }
  // Meshes, point clouds and images become sessions through their first job.
  json request = body;
  request.erase("upload");
  json input = request.value("input", json::object());
  if (kind == "mesh") {
    request["op"] = "cpt";
    input["mesh"] = upload;
  } else if (kind == "points") {
    request["op"] = "reconstruct";
    input["points"] = upload;
  } else if (kind == "image") {
    request["op"] = "segment";
    input["image"] = upload;
  } else {
    throw unprocessable("body.upload", "the upload's kind '" + kind + "' cannot start a session");
  }
  request["input"] = input;
  return submit("", request);
}

json Service::patch_session(const std::string& id, const json& body) {
  auto s = sessions_->get(id);
  if (!body.is_object() || (!body.contains("name") && !body.contains("points")))
    throw bad_request("expected {\"name\": NEW_NAME} and/or {\"points\": UPLOAD_ID | null}");
  for (const auto& [key, value] : body.items())
    if (key != "name" && key != "points") throw unprocessable("body." + key.substr(0, 40), "unknown field (name, points)");
  std::string name;
  if (body.contains("name")) {
    if (!body["name"].is_string()) throw unprocessable("body.name", "expected a string");
    name = body["name"].get<std::string>();
    if (name.empty() || name.size() > 200) throw unprocessable("body.name", "expected 1 to 200 characters");
  }
  if (body.contains("points") && !body["points"].is_null() && !body["points"].is_string())
    throw unprocessable("body.points", "expected an upload id or null");
  if (body.contains("points")) {  // checked before the rename: all or nothing
    if (body["points"].is_null()) sessions_->detach_points(*s);
    else attach_points(*s, body["points"].get<std::string>(), "body.points");
  }
  if (!name.empty()) sessions_->rename(*s, name);
  return s->describe();
}

json Service::put_roi(const std::string& id, const json& body) {
  auto s = sessions_->get(id);
  if (!body.is_object()) throw bad_request("expected {} (the current band) or {\"snapshot\": SNAPSHOT_ID}");
  for (const auto& [key, value] : body.items())
    if (key != "snapshot" && key != "session")
      throw unprocessable("body." + key.substr(0, 40), "unknown field (snapshot, session)");
  if (body.size() > 1) throw unprocessable("body", "give one of snapshot and session");
  if (body.contains("session")) {
    // Another session's committed band (thesis table 4.1 B: a distance field computed with the
    // ROI option becomes the static array of the surface being evolved). Sampled by world
    // position, so the two grids need not match.
    if (!body["session"].is_string()) throw unprocessable("body.session", "expected a session id");
    auto source = sessions_->get(body["session"].get<std::string>());
    sessions_->store_roi(*s, *source->band(), {{"session", source->id()}, {"version", source->version()}});
  } else if (body.contains("snapshot")) {
    if (!body["snapshot"].is_string()) throw unprocessable("body.snapshot", "expected a snapshot id");
    const std::string sid = body["snapshot"].get<std::string>();
    bool known = false;
    for (const json& j : s->snapshots()) known = known || j.value("id", "") == sid;
    if (!known || !is_valid_id(sid, 'n')) throw not_found("snapshot", sid);
    const NarrowBand band = load_lsg(s->dir() / ("snap-" + sid + ".lsg")).band;
    sessions_->store_roi(*s, band, {{"snapshot", sid}});
  } else {
    sessions_->store_roi(*s, *s->band(), {{"version", s->version()}});
  }
  return s->describe();
}

void Service::attach_points(Session& s, const std::string& upload_id, const std::string& place) {
  const json meta = uploads_->get(upload_id);
  if (meta.value("kind", "") != "points")
    throw unprocessable(place, "upload " + upload_id + " is a " + meta.value("kind", "file") + ", not a point cloud");
  const json summary = meta.value("summary", json::object());
  sessions_->attach_points(s, uploads_->path_of(upload_id),
                           {{"upload", upload_id}, {"format", meta.value("format", "xyz")},
                            {"points", summary.value("points", 0)}});
}

Reply Service::snapshot(const std::string& id, const json& body) {
  auto s = sessions_->get(id);
  const json snap = sessions_->snapshot(*s, config_.replica, body.is_object() ? body.value("name", "") : "");
  return {201, snap, "/api/v1/sessions/" + id + "/snapshots"};
}

json Service::restore(const std::string& id, const std::string& snapshot_id) {
  auto s = sessions_->get(id);
  if (!s->claim("restore")) throw conflict("a job runs on session " + id);
  try {
    sessions_->restore(*s, snapshot_id);
  } catch (...) {
    s->release("restore");
    throw;
  }
  s->release("restore");
  return s->describe();
}

// ---- idempotency ----------------------------------------------------------------------------

std::optional<std::pair<int, std::string>> Service::replay(const std::string& key) {
  std::lock_guard lock(idempotency_mutex_);
  auto it = idempotency_.find(key);
  if (it == idempotency_.end()) return std::nullopt;
  return it->second.second;
}

void Service::remember(const std::string& key, int status, const std::string& body) {
  std::lock_guard lock(idempotency_mutex_);
  const auto now = std::chrono::steady_clock::now();
  for (auto it = idempotency_.begin(); it != idempotency_.end();)
    it = now - it->second.first > std::chrono::hours(24) ? idempotency_.erase(it) : std::next(it);
  if (idempotency_.size() >= 10000) idempotency_.erase(idempotency_.begin());
  idempotency_.emplace(key, std::make_pair(now, std::make_pair(status, body)));
}

}  // namespace levelset::service
