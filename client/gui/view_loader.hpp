// ViewLoader: picks the view mode and keeps it fed. Local geometry: the surface of the shown
// session version at the iso value (F) is fetched as PLY with its ETag (a 304 costs nothing),
// and the band (.lsg) when an overlay needs it; while a job runs on the session its latest step
// is asked for twice a second. Remote frames: the session's MJPEG stream.
// "auto" switches to remote frames above the triangle budget, judged before downloading from
// the band's size (active voxels / band half-width ~ surface triangles) and after it from the
// mesh itself. The session's attachments follow its description: its region of influence
// (.lsg) while D shows Point(ROI), and its point cloud (as uploaded) while I shows points.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "app_state.hpp"
#include "net_worker.hpp"
#include "remote_view.hpp"
#include "scene_view.hpp"

namespace levelset::gui {

std::uint64_t estimated_triangles(const nlohmann::json& session);

class ViewLoader {
 public:
  ViewLoader(const ApiHolder& api, Inbox& inbox, Worker& fetches, SceneView& local, RemoteView& remote)
      : api_(api), inbox_(inbox), fetches_(fetches), local_(local), remote_(remote) {}

  // UI thread, once a frame; w x h is the scene's size in pixels.
  void update(AppState& s, int w, int h);
  void refetch() { mesh_key_.clear(), band_key_.clear(), roi_key_.clear(), points_key_.clear(); }

 private:
  void fetch_mesh(AppState& s);
  void fetch_band(AppState& s);
  void update_attachments(AppState& s);
  // GET path of the shown session on the fetch thread; `decode` (on that thread) turns the body
  // into what the UI thread applies if the session is still shown.
  using Decoded = std::function<void(AppState&)>;
  void fetch_part(AppState& s, const std::string& path, const std::string& what,
                  std::function<Decoded(const std::string& body)> decode);
  const ApiHolder& api_;
  Inbox& inbox_;
  Worker& fetches_;
  SceneView& local_;
  RemoteView& remote_;
  std::string session_;            // the session the local scene belongs to
  std::string mesh_key_, band_key_;  // what was last asked for: session@version@iso
  std::string roi_key_, points_key_;  // session + the attachment's description
  std::string etag_;
  // The frame stream's size follows the window only once a resize has settled (0.3 s): each
  // new size opens a new stream.
  int stream_w_ = 0, stream_h_ = 0, asked_w_ = 0, asked_h_ = 0;
  double asked_since_ = 0;
  // While a job runs on the shown session the mesh route serves its latest step (a new ETag):
  // asked again every 0.5 s, one request at a time.
  double polled_at_ = 0;
  std::shared_ptr<std::atomic<bool>> mesh_in_flight_ = std::make_shared<std::atomic<bool>>(false);
};

}  // namespace levelset::gui
