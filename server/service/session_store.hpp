// Sessions: named narrow bands held in memory, each with a version, a history of the
// operations that made it, snapshots and an event log; persisted under DATA/sessions/<id>/.
//
// Layout: session.json (metadata; names the band file), band-v<N>.lsg (the committed band),
// snap-<sid>.lsg (snapshots), checkpoint-<job>.lsg + .json (a long job's latest state).
// Every file is written atomically (temp, fsync, rename); a commit writes the new band file
// first and session.json second, then removes the old band, so kill -9 at any point leaves the
// last committed version loadable.
// Readers get immutable shared_ptr bands: a running job never blocks them, and a preview (the
// latest step of an evolution, at most every ~100 ms) is seen through preview().
// Limits: sessions, voxels per session and all bands' memory, checked before a band is taken
// in (ApiError 507). Threading: all members thread-safe.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"
#include "service/event_log.hpp"

namespace levelset::service {

struct SessionLimits {
  int max_sessions = 256;
  std::uint64_t max_session_voxels = std::uint64_t{1} << 28;
  std::uint64_t max_band_memory = std::uint64_t{4} << 30;
};

class Session {
 public:
  Session(std::string id, std::filesystem::path dir) : id_(std::move(id)), dir_(std::move(dir)) {}

  const std::string& id() const { return id_; }
  const std::filesystem::path& dir() const { return dir_; }
  std::shared_ptr<const NarrowBand> band() const;
  std::shared_ptr<const NarrowBand> preview() const;  // the running job's latest step, else band()
  std::uint64_t version() const;
  std::uint64_t preview_serial() const { return preview_serial_.load(); }  // changes with the band state
  std::uint64_t view_serial() const { return view_serial_.load(); }        // changes with the view
  nlohmann::json describe() const;  // id, name, version, created, updated, band summary, history size
  nlohmann::json history() const;
  nlohmann::json snapshots() const;
  nlohmann::json view() const;  // the camera and display settings of this session's frames
  // The session's point cloud (its reconstruction input, or a point upload attached with PATCH),
  // read on first use and kept; null when it has none. points_serial() changes with it.
  std::shared_ptr<const PointCloud> points() const;
  std::uint64_t points_serial() const { return points_serial_.load(); }
  // The session's region of influence (thesis table 4.1 B and D: a stored copy of a distance
  // field that speed formulas read as `roi`), read on first use; null when it has none.
  std::shared_ptr<const NarrowBand> roi() const;
  std::uint64_t roi_serial() const { return roi_serial_.load(); }
  // Changes whenever a frame of the session would: its band state, view, point cloud or ROI.
  std::uint64_t frame_state() const {
    return ((preview_serial_.load() * 1000003 + view_serial_.load()) * 1009 + points_serial_.load()) * 1013 +
           roi_serial_.load();
  }
  EventLog& events() { return events_; }

  // One job at a time: claim() is false when another holds the session.
  bool claim(const std::string& job_id);
  void release(const std::string& job_id);
  std::string running_job() const;

 private:
  friend class SessionStore;
  mutable std::mutex mutex_;
  std::string id_;
  std::filesystem::path dir_;
  nlohmann::json meta_ = nlohmann::json::object();  // what session.json holds
  std::shared_ptr<const NarrowBand> band_, preview_;
  nlohmann::json summary_;  // band_summary(*band_), computed once per version (GETs are hot)
  std::atomic<std::uint64_t> preview_serial_{0}, view_serial_{0}, points_serial_{0}, roi_serial_{0};
  mutable std::mutex points_mutex_;  // reading the cloud (or the ROI) does not hold mutex_
  mutable std::shared_ptr<const PointCloud> points_;
  mutable std::string points_file_;
  mutable std::shared_ptr<const NarrowBand> roi_;
  mutable std::string roi_file_;
  std::string running_job_;
  EventLog events_;
};

class SessionStore {
 public:
  SessionStore(std::filesystem::path dir, SessionLimits limits);

  // Loads every session found on disk; returns one line per session that could not be loaded.
  std::vector<std::string> load_all();

  std::shared_ptr<Session> create(const std::string& replica, const std::string& name, NarrowBand band,
                                  nlohmann::json source);
  std::shared_ptr<Session> get(const std::string& id) const;  // ApiError 404
  std::vector<std::shared_ptr<Session>> list() const;
  void rename(Session& s, const std::string& name);
  void remove(const std::string& id);  // ApiError 409 while a job runs

  // Persists the band as the next version and swaps it in; history gets `entry`.
  std::uint64_t commit(Session& s, NarrowBand band, nlohmann::json entry);
  void set_preview(Session& s, std::shared_ptr<const NarrowBand> band);
  // Merges `changes` into the session's view settings (kept in session.json); publishes "view".
  nlohmann::json update_view(Session& s, const nlohmann::json& changes);
  void clear_preview(Session& s);
  // Keeps a copy of a point-cloud file (a hard link when it can) as the session's cloud; `info`
  // (upload id, format, point count) is what describe() shows. Publishes "points".
  void attach_points(Session& s, const std::filesystem::path& file, nlohmann::json info);
  void detach_points(Session& s);
  // Stores `band` as the session's region of influence (roi-<serial>.lsg); `info` (what it was
  // made from) is what describe() shows with its summary. Publishes "roi".
  nlohmann::json store_roi(Session& s, const NarrowBand& band, nlohmann::json info);
  void remove_roi(Session& s);

  nlohmann::json snapshot(Session& s, const std::string& replica, const std::string& name);
  std::uint64_t restore(Session& s, const std::string& snapshot_id);

  void save_checkpoint(Session& s, const std::string& job_id, const NarrowBand& band, const nlohmann::json& state);
  std::optional<std::pair<NarrowBand, nlohmann::json>> load_checkpoint(Session& s, const std::string& job_id) const;
  void drop_checkpoint(Session& s, const std::string& job_id);

  // Refuses (507) a band the limits do not allow; `replacing` is the band it would replace.
  void check_budget(const NarrowBand& band, const NarrowBand* replacing) const;
  std::uint64_t band_memory() const;
  std::size_t count() const;

 private:
  void write_meta(Session& s);  // under s.mutex_
  bool drop_attachment(Session& s, const char* key);  // the points / roi entry and its file

  std::filesystem::path dir_;
  SessionLimits limits_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Session>> sessions_;
};

// The summary of a band the API shows: voxels, bricks, voxel size, half-width, bounds, memory.
nlohmann::json band_summary(const NarrowBand& band);

}  // namespace levelset::service
