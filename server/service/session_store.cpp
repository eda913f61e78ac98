#include "service/session_store.hpp"

#include <system_error>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "grid/lsg_file.hpp"
#include "io/point_cloud_reader.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"
#include "service/render_service.hpp"

namespace levelset::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json bbox_json(const BBox& b) {
  if (b.empty()) return nullptr;
  return {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
}

void write_json(const fs::path& path, const json& j) {
  write_file_atomically(path, j.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
}

json read_json(const fs::path& path) {
  const std::string bytes = read_file_bytes(path, std::uint64_t{64} << 20);
  json j = json::parse(bytes, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw Error(ErrorCode::Corrupt, path.string(), "not a JSON object");
  return j;
}

}  // namespace

json band_summary(const NarrowBand& band) {
  return {{"active_voxels", band.active_voxel_count()},
          {"bricks", band.brick_count()},
          {"voxel_size", band.voxel_size()},
          {"half_width_voxels", band.half_width()},
          {"memory_bytes", band.memory_bytes()},
          {"far_inside", band.far_inside()},
          {"bounds", bbox_json(band.active_world_bounds())}};
}

// ---- Session --------------------------------------------------------------------------------

std::shared_ptr<const NarrowBand> Session::band() const {
  std::lock_guard lock(mutex_);
  return band_;
}

std::shared_ptr<const NarrowBand> Session::preview() const {
  std::lock_guard lock(mutex_);
  return preview_ ? preview_ : band_;
}

std::uint64_t Session::version() const {
  std::lock_guard lock(mutex_);
  return meta_.value("version", std::uint64_t{0});
}

json Session::describe() const {
  std::lock_guard lock(mutex_);
  json j = {{"id", id_},
            {"name", meta_.value("name", "")},
            {"version", meta_.value("version", 0)},
            {"created", meta_.value("created", "")},
            {"updated", meta_.value("updated", "")},
            {"source", meta_.value("source", json::object())},
            {"history_length", meta_.value("history", json::array()).size()},
            {"snapshots", meta_.value("snapshots", json::array()).size()},
            {"running_job", running_job_.empty() ? json(nullptr) : json(running_job_)},
            {"points", meta_.value("points", json(nullptr))},
            {"roi", meta_.value("roi", json(nullptr))}};
  if (band_) j["band"] = summary_;
  return j;
}

std::shared_ptr<const PointCloud> Session::points() const {
  std::string file;
  {
    std::lock_guard lock(mutex_);
    if (!meta_.contains("points") || !meta_["points"].is_object()) return nullptr;
    file = meta_["points"].value("file", "");
  }
  std::lock_guard lock(points_mutex_);
  if (!points_ || points_file_ != file) {  // file names carry the upload id: a new cloud, a new name
    points_file_ = file;
    try {
      points_ = std::make_shared<const PointCloud>(read_point_cloud(dir_ / file).cloud);
    } catch (const Error&) {  // a damaged copy: frames go on without it (describe() still names it)
      points_ = std::make_shared<const PointCloud>();
    }
  }
  return points_;
}

std::shared_ptr<const NarrowBand> Session::roi() const {
  std::string file;
  {
    std::lock_guard lock(mutex_);
    if (!meta_.contains("roi") || !meta_["roi"].is_object()) return nullptr;
    file = meta_["roi"].value("file", "");
  }
  std::lock_guard lock(points_mutex_);
  if (!roi_ || roi_file_ != file) {  // a new ROI has a new file name
    roi_ = std::make_shared<const NarrowBand>(load_lsg(dir_ / file).band);
    roi_file_ = file;
  }
  return roi_;
}

json Session::history() const {
  std::lock_guard lock(mutex_);
  return meta_.value("history", json::array());
}

json Session::snapshots() const {
  std::lock_guard lock(mutex_);
  return meta_.value("snapshots", json::array());
}

json Session::view() const {
  std::lock_guard lock(mutex_);
  return meta_.value("view", json::object());
}

bool Session::claim(const std::string& job_id) {
  std::lock_guard lock(mutex_);
  if (!running_job_.empty()) return false;
  running_job_ = job_id;
  return true;
}

void Session::release(const std::string& job_id) {
  std::lock_guard lock(mutex_);
  if (running_job_ == job_id) running_job_.clear();
}

std::string Session::running_job() const {
  std::lock_guard lock(mutex_);
  return running_job_;
}

// ---- SessionStore ---------------------------------------------------------------------------

SessionStore::SessionStore(fs::path dir, SessionLimits limits) : dir_(std::move(dir)), limits_(limits) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw Error(ErrorCode::IoError, dir_.string(), "cannot create the sessions directory: " + ec.message());
}

std::vector<std::string> SessionStore::load_all() {
  std::vector<std::string> problems;
  std::error_code ec;
  for (const fs::directory_entry& d : fs::directory_iterator(dir_, ec)) {
    const std::string id = d.path().filename().string();
    if (!d.is_directory() || !is_valid_id(id, 's')) continue;
    // A directory without session.json is a creation cut short (kill -9 between mkdir and the
    // first metadata write): no client was ever told of it.
    if (!fs::exists(d.path() / "session.json", ec)) {
      fs::remove_all(d.path(), ec);
      continue;
    }
    try {
      json meta = read_json(d.path() / "session.json");
      const std::string band_file = meta.value("band_file", "");
      if (band_file.find('/') != std::string::npos || band_file.empty())
        throw Error(ErrorCode::Corrupt, (d.path() / "session.json").string(), "no band file named");
      auto s = std::make_shared<Session>(id, d.path());
      s->band_ = std::make_shared<const NarrowBand>(load_lsg(d.path() / band_file).band);
      s->summary_ = band_summary(*s->band_);
      s->meta_ = std::move(meta);
      // Leftovers of a commit cut short: band files other than the named one.
      for (const fs::directory_entry& f : fs::directory_iterator(d.path(), ec)) {
        const std::string name = f.path().filename().string();
        if (name.rfind("band-v", 0) == 0 && name != band_file) fs::remove(f.path(), ec);
        if (name.find(".tmp-") != std::string::npos) fs::remove(f.path(), ec);
      }
      std::lock_guard lock(mutex_);
      sessions_[id] = std::move(s);
    } catch (const Error& e) {
      problems.push_back(id + ": " + e.what());
    }
  }
  return problems;
}

void SessionStore::check_budget(const NarrowBand& band, const NarrowBand* replacing) const {
  if (band.active_voxel_count() > limits_.max_session_voxels)
    throw ApiError(507, "limit_exceeded",
                   "the band has " + std::to_string(band.active_voxel_count()) + " active voxels, more than the " +
                       std::to_string(limits_.max_session_voxels) + " a session may hold (max_session_voxels)");
  const std::uint64_t total = band_memory() + band.memory_bytes() - (replacing ? replacing->memory_bytes() : 0);
  if (total > limits_.max_band_memory)
    throw ApiError(507, "limit_exceeded",
                   "the sessions' bands would take " + std::to_string(total) + " bytes, more than max_band_memory (" +
                       std::to_string(limits_.max_band_memory) + ")");
}

std::uint64_t SessionStore::band_memory() const {
  std::lock_guard lock(mutex_);
  std::uint64_t total = 0;
  for (const auto& [id, s] : sessions_)
    if (auto b = s->band()) total += b->memory_bytes();
  return total;
}

std::size_t SessionStore::count() const {
  std::lock_guard lock(mutex_);
  return sessions_.size();
}

void SessionStore::write_meta(Session& s) { write_json(s.dir_ / "session.json", s.meta_); }

std::shared_ptr<Session> SessionStore::create(const std::string& replica, const std::string& name, NarrowBand band,
                                              json source) {
  if (int(count()) >= limits_.max_sessions)
    throw ApiError(507, "limit_exceeded", "the server holds " + std::to_string(count()) + " sessions (max_sessions)");
  check_budget(band, nullptr);
  const std::string id = new_id(replica, 's');
  auto s = std::make_shared<Session>(id, dir_ / id);
  std::error_code ec;
  fs::create_directories(s->dir_, ec);
  if (ec) throw Error(ErrorCode::IoError, s->dir_.string(), "cannot create the session directory: " + ec.message());
  const std::string now = now_iso();
  s->meta_ = {{"id", id},         {"name", name.empty() ? id : name}, {"version", 1},
              {"created", now},   {"updated", now},                   {"source", std::move(source)},
              {"band_file", "band-v1.lsg"}, {"history", json::array()}, {"snapshots", json::array()}};
  s->meta_["history"].push_back({{"version", 1}, {"op", "create"}, {"time", now}});
  try {
    save_lsg(band, s->dir_ / "band-v1.lsg");
    write_meta(*s);
  } catch (...) {
    fs::remove_all(s->dir_, ec);
    throw;
  }
  s->band_ = std::make_shared<const NarrowBand>(std::move(band));
  s->summary_ = band_summary(*s->band_);
  std::lock_guard lock(mutex_);
  sessions_[id] = s;
  return s;
}

std::shared_ptr<Session> SessionStore::get(const std::string& id) const {
  std::lock_guard lock(mutex_);
  auto it = sessions_.find(id);
  if (it == sessions_.end()) throw not_found("session", id);
  return it->second;
}

std::vector<std::shared_ptr<Session>> SessionStore::list() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<Session>> out;
  for (const auto& [id, s] : sessions_) out.push_back(s);
  return out;
}

void SessionStore::rename(Session& s, const std::string& name) {
  std::lock_guard lock(s.mutex_);
  s.meta_["name"] = name;
  s.meta_["updated"] = now_iso();
  write_meta(s);
}

void SessionStore::remove(const std::string& id) {
  std::shared_ptr<Session> s = get(id);
  if (!s->running_job().empty()) throw conflict("a job runs on session " + id + "; cancel it first");
  {
    std::lock_guard lock(mutex_);
    sessions_.erase(id);
  }
  s->events().publish("deleted", {{"id", id}});
  s->events().close();
  std::error_code ec;
  fs::remove_all(s->dir_, ec);
}

std::uint64_t SessionStore::commit(Session& s, NarrowBand band, json entry) {
  std::uint64_t version;
  check_budget(band, s.band().get());  // before the session's lock: band_memory() takes them all
  {
    std::lock_guard lock(s.mutex_);
    version = s.meta_.value("version", std::uint64_t{0}) + 1;
    const std::string old_file = s.meta_.value("band_file", "");
    const std::string file = "band-v" + std::to_string(version) + ".lsg";
    save_lsg(band, s.dir_ / file);
    json meta = s.meta_;
    meta["version"] = version;
    meta["band_file"] = file;
    meta["updated"] = now_iso();
    entry["version"] = version;
    entry["time"] = meta["updated"];
    meta["history"].push_back(std::move(entry));
    std::swap(s.meta_, meta);
    try {
      write_meta(s);
    } catch (...) {
      std::swap(s.meta_, meta);
      std::error_code ec;
      fs::remove(s.dir_ / file, ec);
      throw;
    }
    std::error_code ec;
    if (!old_file.empty() && old_file != file) fs::remove(s.dir_ / old_file, ec);
    s.band_ = std::make_shared<const NarrowBand>(std::move(band));
    s.summary_ = band_summary(*s.band_);
    s.preview_.reset();
  }
  s.preview_serial_.fetch_add(1);
  s.events().publish("version", {{"version", version}});
  return version;
}

void SessionStore::set_preview(Session& s, std::shared_ptr<const NarrowBand> band) {
  {
    std::lock_guard lock(s.mutex_);
    s.preview_ = std::move(band);
  }
  s.preview_serial_.fetch_add(1);
}

void SessionStore::clear_preview(Session& s) { set_preview(s, nullptr); }

void SessionStore::attach_points(Session& s, const fs::path& file, json info) {
  const std::string name = "points-" + info.value("upload", "cloud") + "." + info.value("format", "xyz");
  const fs::path target = s.dir_ / name, temp = s.dir_ / (name + ".tmp-attach");
  std::error_code ec;
  fs::remove(temp, ec);
  fs::create_hard_link(file, temp, ec);
  if (ec) {
    ec.clear();
    fs::copy_file(file, temp, fs::copy_options::overwrite_existing, ec);
  }
  if (!ec) fs::rename(temp, target, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw Error(ErrorCode::IoError, name, "cannot keep the point cloud with the session: " + ec.message());
  }
  info["file"] = name;
  {
    std::lock_guard lock(s.mutex_);
    const std::string old = s.meta_.contains("points") ? s.meta_["points"].value("file", "") : "";
    s.meta_["points"] = info;
    write_meta(s);
    if (!old.empty() && old != name) fs::remove(s.dir_ / old, ec);
  }
  s.points_serial_.fetch_add(1);
  s.events().publish("points", info);
}

json SessionStore::store_roi(Session& s, const NarrowBand& band, json info) {
  const std::string name = "roi-" + std::to_string(s.roi_serial_.load() + 1) + "-" + now_iso().substr(0, 19) + ".lsg";
  std::string file = name;
  for (char& c : file)
    if (c == ':') c = '-';
  save_lsg(band, s.dir_ / file);
  info["file"] = file;
  info["active_voxels"] = band.active_voxel_count();
  info["voxel_size"] = band.voxel_size();
  info["time"] = now_iso();
  {
    std::lock_guard lock(s.mutex_);
    const std::string old = s.meta_.contains("roi") ? s.meta_["roi"].value("file", "") : "";
    s.meta_["roi"] = info;
    write_meta(s);
    std::error_code ec;
    if (!old.empty() && old != file) fs::remove(s.dir_ / old, ec);
  }
  s.roi_serial_.fetch_add(1);
  s.events().publish("roi", info);
  return info;
}

// Removes the attachment `key` (its metadata and its file); false when there was none.
bool SessionStore::drop_attachment(Session& s, const char* key) {
  std::lock_guard lock(s.mutex_);
  if (!s.meta_.contains(key)) return false;
  const std::string old = s.meta_[key].value("file", "");
  s.meta_.erase(key);
  write_meta(s);
  std::error_code ec;
  if (!old.empty()) fs::remove(s.dir_ / old, ec);
  return true;
}

void SessionStore::remove_roi(Session& s) {
  if (!drop_attachment(s, "roi")) return;
  s.roi_serial_.fetch_add(1);
  s.events().publish("roi", nullptr);
}

void SessionStore::detach_points(Session& s) {
  if (!drop_attachment(s, "points")) return;
  s.points_serial_.fetch_add(1);
  s.events().publish("points", nullptr);
}

json SessionStore::update_view(Session& s, const json& changes) {
  json view;
  {
    std::lock_guard lock(s.mutex_);
    json merged = s.meta_.value("view", json::object());
    merged.merge_patch(changes);
    if (merged.dump().size() > 16384) throw unprocessable("body", "the view settings are larger than 16 KiB");
    check_view_settings(merged);  // refused here (422 naming the field), never later per frame
    s.meta_["view"] = merged;
    write_meta(s);
    view = merged;
  }
  s.view_serial_.fetch_add(1);  // streams redraw
  s.events().publish("view", view);
  return view;
}

json SessionStore::snapshot(Session& s, const std::string& replica, const std::string& name) {
  const std::string sid = new_id(replica, 'n');
  std::lock_guard lock(s.mutex_);
  save_lsg(*s.band_, s.dir_ / ("snap-" + sid + ".lsg"));
  json snap = {{"id", sid},
               {"name", name.empty() ? sid : name},
               {"version", s.meta_.value("version", 0)},
               {"created", now_iso()}};
  s.meta_["snapshots"].push_back(snap);
  write_meta(s);
  return snap;
}

std::uint64_t SessionStore::restore(Session& s, const std::string& snapshot_id) {
  json snap;
  for (const json& j : s.snapshots())
    if (j.value("id", "") == snapshot_id) snap = j;
  if (snap.is_null()) throw not_found("snapshot", snapshot_id);
  NarrowBand band = load_lsg(s.dir_ / ("snap-" + snapshot_id + ".lsg")).band;
  return commit(s, std::move(band), {{"op", "restore"}, {"snapshot", snapshot_id}, {"from_version", snap["version"]}});
}

void SessionStore::save_checkpoint(Session& s, const std::string& job_id, const NarrowBand& band, const json& state) {
  save_lsg(band, s.dir_ / ("checkpoint-" + job_id + ".lsg"));
  write_json(s.dir_ / ("checkpoint-" + job_id + ".json"), state);
}

std::optional<std::pair<NarrowBand, json>> SessionStore::load_checkpoint(Session& s, const std::string& job_id) const {
  std::error_code ec;
  const fs::path band = s.dir_ / ("checkpoint-" + job_id + ".lsg"), state = s.dir_ / ("checkpoint-" + job_id + ".json");
  if (!fs::exists(band, ec) || !fs::exists(state, ec)) return std::nullopt;
  return std::make_pair(load_lsg(band).band, read_json(state));
}

void SessionStore::drop_checkpoint(Session& s, const std::string& job_id) {
  std::error_code ec;
  fs::remove(s.dir_ / ("checkpoint-" + job_id + ".lsg"), ec);
  fs::remove(s.dir_ / ("checkpoint-" + job_id + ".json"), ec);
}

}  // namespace levelset::service
