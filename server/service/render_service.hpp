// RenderService: the daemon's offscreen frames. One render thread owns the GL context (EGL
// surfaceless or OSMesa, created on that thread at start; HTTP threads never call GL) and
// serves frame requests from a queue: the session's current state (its preview while a job
// runs, else its committed band) is contoured and uploaded once per state, then drawn with the
// requested view and encoded (JPEG or PNG).
//
// The GL work sits behind SceneRenderer, made by a factory on the render thread, so this file
// knows nothing of OpenGL: levelset_render provides the real one (render_backend.cpp).
// With mode "off", or when no context can be made, available() is false and status() says why;
// the frame routes answer 503 with it and everything else keeps working.
// Threading: render() from any thread (blocks until the frame is drawn or the timeout passes).
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::service {

struct EncodedFrame {
  std::shared_ptr<const std::string> bytes;
  std::string content_type;  // image/jpeg, image/png
  int width = 0, height = 0;
};

// What the daemon needs from a renderer; lives on the render thread only.
class SceneRenderer {
 public:
  virtual ~SceneRenderer() = default;
  virtual std::string name() const = 0;  // the GL renderer string, for the log
  // The scene: the band (field displays, slice, volume), its surface mesh, the session's
  // point cloud and region of influence (null: none).
  virtual void set_scene(std::shared_ptr<const NarrowBand> band, const TriangleMesh& surface,
                         std::shared_ptr<const PointCloud> points, std::shared_ptr<const NarrowBand> roi) = 0;
  // view: the session's view settings (JSON), then the request's query parameters over them
  // (key=value as in the URL); both validated here (levelset::Error naming the setting).
  virtual EncodedFrame render(const nlohmann::json& view, const std::vector<std::pair<std::string, std::string>>& query,
                              int width, int height, const std::string& format, int quality) = 0;
};
using RendererFactory = std::function<std::unique_ptr<SceneRenderer>(const std::string& mode)>;

struct FrameRequest {
  std::string scene_key;                     // session id + state serial: scenes are reused by key
  std::shared_ptr<const NarrowBand> band;    // the state to draw
  std::shared_ptr<const PointCloud> points;  // the session's point cloud, or null
  std::shared_ptr<const NarrowBand> roi;     // the session's region of influence, or null
  nlohmann::json view = nlohmann::json::object();
  std::vector<std::pair<std::string, std::string>> query;  // view settings from the URL
  int width = 800, height = 600;
  std::string format = "jpeg";
  int quality = 85;
};

class RenderService {
 public:
  RenderService(const std::string& mode, RendererFactory factory);
  ~RenderService();

  bool available() const;
  std::string status() const;  // "egl: llvmpipe (...)" or why rendering is off
  // Draws a frame on the render thread: ApiError 503 when unavailable or past `timeout`.
  EncodedFrame render(FrameRequest request, std::chrono::milliseconds timeout);
  std::uint64_t frames_rendered() const { return frames_.load(); }

 private:
  void loop(const std::string& mode, RendererFactory factory, std::promise<void> started);

  struct Task {
    FrameRequest request;
    std::promise<EncodedFrame> result;
  };
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Task>> tasks_;
  bool stopping_ = false, available_ = false;
  std::string status_;
  std::atomic<std::uint64_t> frames_{0};
  std::thread thread_;
};

// The renderer levelset_render provides (render_backend.cpp), or null when the build has none.
RendererFactory default_renderer_factory();
// Checks a session's view settings as the renderer will read them (levelset::Error naming the
// field); no-op in builds without a renderer. Any thread (no GL).
void check_view_settings(const nlohmann::json& view);

}  // namespace levelset::service
