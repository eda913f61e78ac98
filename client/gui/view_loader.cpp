#include "view_loader.hpp"

#include <chrono>
#include <cstdio>

#include "grid/lsg_file.hpp"
#include "io/mesh_reader.hpp"
#include "io/point_cloud_reader.hpp"

namespace levelset::gui {

using nlohmann::json;
using client::Api;

std::uint64_t estimated_triangles(const json& session) {
  if (!session.is_object() || !session.contains("band") || !session["band"].is_object()) return 0;
  const json& b = session["band"];
  const double voxels = b.value("active_voxels", 0.0), half_width = std::max(1.0, b.value("half_width_voxels", 3.0));
  return std::uint64_t(voxels / half_width);
}

void ViewLoader::update(AppState& s, int w, int h) {
  const PanelState& p = s.panel;
  const std::uint64_t budget = std::uint64_t(std::max(1, p.triangle_budget));
  s.remote = p.view_mode == 2 ||
             (p.view_mode == 0 && !s.current.empty() && (estimated_triangles(s.session) > budget || s.mesh_triangles > budget));
  const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  if (w != asked_w_ || h != asked_h_) asked_w_ = w, asked_h_ = h, asked_since_ = now;
  if (stream_w_ == 0 || now - asked_since_ > 0.3) stream_w_ = asked_w_, stream_h_ = asked_h_;
  remote_.show(s.remote && s.connected ? s.current : "", stream_w_, stream_h_);
  if (s.current.empty() && !session_.empty()) {
    // No session shown (a loaded mesh file may be): the next one shown is fetched afresh.
    session_.clear();
    mesh_key_.clear();
    band_key_.clear();
    roi_key_.clear();
    points_key_.clear();
    etag_.clear();
  }
  if (s.current != session_ && !s.current.empty()) {
    // Another session: drop what was shown (the last session's geometry or a loaded mesh file).
    local_.clear();
    session_ = s.current;
    s.mesh_triangles = 0;
    s.mesh_version = -1;
    s.band_loaded = false;
    s.roi_loaded = false;
    s.cloud_points = 0;
    mesh_key_.clear();
    band_key_.clear();
    roi_key_.clear();
    points_key_.clear();
    etag_.clear();
  }
  if (s.remote || s.current.empty() || s.version() <= 0 || !s.connected) return;
  char iso[32];
  std::snprintf(iso, sizeof iso, "%.6g", double(s.iso_shown));
  const std::string key = s.current + "@" + std::to_string(s.version()) + "@" + iso;
  bool job_running = false;
  for (const JobRow& j : s.jobs) job_running = job_running || (j.session == s.current && j.state == "running");
  if (key != mesh_key_ || (job_running && now - polled_at_ > 0.5 && !mesh_in_flight_->load())) {
    mesh_key_ = key;
    polled_at_ = now;
    fetch_mesh(s);
  }
  const bool overlays = p.field != 0 || p.slice != 0 || p.volume;
  const std::string band_key = s.current + "@" + std::to_string(s.version());
  if (overlays && band_key != band_key_) {
    band_key_ = band_key;
    fetch_band(s);
  }
  update_attachments(s);
}

// The region of influence and the point cloud: fetched when shown and changed (a new ROI has a
// new file; a new cloud a new upload), dropped when the session no longer has one.
void ViewLoader::update_attachments(AppState& s) {
  const PanelState& p = s.panel;
  const nlohmann::json none;
  const nlohmann::json& roi = s.session.is_object() && s.session.contains("roi") ? s.session["roi"] : none;
  if (p.field == 5 && roi.is_object()) {
    const std::string key = s.current + roi.dump();
    if (key != roi_key_) {
      roi_key_ = key;
      fetch_part(s, "/roi", "region of influence", [this](const std::string& body) -> Decoded {
        auto band = std::make_shared<const NarrowBand>(decode_lsg(body, "roi.lsg").band);
        return [this, band](AppState& st) { local_.set_roi(band), st.roi_loaded = true; };
      });
    }
  } else if (!roi_key_.empty() && !roi.is_object()) {
    roi_key_.clear();
    local_.set_roi(nullptr);
    s.roi_loaded = false;
  }
  const nlohmann::json& points = s.session.is_object() && s.session.contains("points") ? s.session["points"] : none;
  if (p.cloud == 1 && points.is_object()) {
    const std::string key = s.current + points.dump();
    if (key != points_key_) {
      points_key_ = key;
      const std::string name = "points." + points.value("format", std::string("xyz"));
      fetch_part(s, "/points", "point cloud", [this, name](const std::string& body) -> Decoded {
        auto cloud = std::make_shared<PointCloud>(read_point_cloud_from_memory(body, name).cloud);
        return [this, cloud](AppState& st) {
          st.cloud_points = cloud->points.size();
          local_.set_points(std::move(*cloud));
        };
      });
    }
  } else if (!points_key_.empty() && !points.is_object()) {
    points_key_.clear();
    local_.set_points(PointCloud{});
    s.cloud_points = 0;
  }
}

void ViewLoader::fetch_part(AppState& s, const std::string& path, const std::string& what,
                            std::function<Decoded(const std::string& body)> decode) {
  auto api = api_.get();
  if (!api) return;
  const std::string session = s.current;
  fetches_.post([this, api, session, path, what, decode] {
    try {
      Api::Raw raw = api->get_raw("/api/v1/sessions/" + Api::encode(session) + path);
      Decoded apply = decode(raw.body);
      inbox_.post([session, apply](AppState& st) {
        if (st.current == session) apply(st);
      });
    } catch (const std::exception& e) {
      inbox_.post([session, what, why = describe_error(e)](AppState& st) {
        if (st.current == session) st.add_error(what + " of " + session + ": " + why);
      });
    }
  });
}

void ViewLoader::fetch_mesh(AppState& s) {
  auto api = api_.get();
  if (!api) return;
  char iso[32];
  std::snprintf(iso, sizeof iso, "%.9g", double(s.iso_shown));
  const std::string path = "/api/v1/sessions/" + Api::encode(s.current) + "/mesh?format=ply&iso=" + iso;
  const std::string session = s.current, etag = etag_;
  const int version = s.version();
  *mesh_in_flight_ = true;
  fetches_.post([this, api, path, session, etag, version, flag = mesh_in_flight_] {
    struct Done {  // cleared however the request ends
      std::atomic<bool>& f;
      ~Done() { f = false; }
    } done{*flag};
    try {
      Api::Raw raw = api->get_raw(path, etag);
      if (raw.status == 304) {
        inbox_.post([session, version](AppState& st) {
          if (st.current == session) st.mesh_version = version;
        });
        return;
      }
      auto mesh = std::make_shared<TriangleMesh>(read_mesh_from_memory(raw.body, "mesh.ply").mesh);
      // The moving view's simplified copy, made here rather than on the UI thread.
      auto simplified = std::make_shared<const std::vector<std::uint32_t>>(
          render::motion_indices(*mesh, SceneView::options()));
      inbox_.post([this, session, version, mesh, simplified, tag = raw.etag](AppState& st) {
        if (st.current != session) return;
        etag_ = tag;
        st.mesh_triangles = mesh->triangles.size();
        st.mesh_version = version;
        local_.set_mesh(std::move(*mesh), simplified);
      });
    } catch (const std::exception& e) {
      inbox_.post([session, why = describe_error(e)](AppState& st) {
        if (st.current == session) st.add_error("surface of " + session + ": " + why);
      });
    }
  });
}

void ViewLoader::fetch_band(AppState& s) {
  fetch_part(s, "/band", "band", [this](const std::string& body) -> Decoded {
    auto band = std::make_shared<const NarrowBand>(decode_lsg(body, "band.lsg").band);
    return [this, band](AppState& st) { local_.set_band(band), st.band_loaded = true; };
  });
}

}  // namespace levelset::gui
