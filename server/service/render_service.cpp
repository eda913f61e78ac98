#include "service/render_service.hpp"

#include "core/error.hpp"
#include "service/api_error.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::service {

RenderService::RenderService(const std::string& mode, RendererFactory factory) {
  if (mode == "off" || !factory) {
    status_ = mode == "off" ? "rendering is off (levelsetd serve --render off)" : "this build has no renderer";
    return;
  }
  std::promise<void> started;
  std::future<void> ready = started.get_future();
  thread_ = std::thread([this, mode, factory, s = std::move(started)]() mutable { loop(mode, factory, std::move(s)); });
  ready.wait();  // the context exists (or failed) before the daemon says it is listening
}

RenderService::~RenderService() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool RenderService::available() const {
  std::lock_guard lock(mutex_);
  return available_;
}

std::string RenderService::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

void RenderService::loop(const std::string& mode, RendererFactory factory, std::promise<void> started) {
  std::unique_ptr<SceneRenderer> renderer;
  try {
    renderer = factory(mode);
    std::lock_guard lock(mutex_);
    available_ = true;
    status_ = mode + ": " + renderer->name();
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    status_ = "no working " + mode + " context: " + e.what();
  }
  started.set_value();
  if (!renderer) return;
  std::string scene_key;
  for (;;) {
    std::shared_ptr<Task> task;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || !tasks_.empty(); });
      if (stopping_) break;
      task = tasks_.front();
      tasks_.pop_front();
    }
    try {
      const FrameRequest& r = task->request;
      if (r.scene_key != scene_key) {
        // A new state: contour it once; frames of the same state reuse the upload.
        const TriangleMesh surface = r.band->active_voxel_count() > 0 ? marching_cubes(*r.band).mesh : TriangleMesh{};
        renderer->set_scene(r.band, surface, r.points, r.roi);
        scene_key = r.scene_key;
      }
      task->result.set_value(renderer->render(r.view, r.query, r.width, r.height, r.format, r.quality));
      ++frames_;
    } catch (...) {
      scene_key.clear();
      task->result.set_exception(std::current_exception());
    }
  }
  std::lock_guard lock(mutex_);
  for (auto& t : tasks_) t->result.set_exception(std::make_exception_ptr(ApiError(503, "shutting_down", "the server is stopping")));
  tasks_.clear();
}

EncodedFrame RenderService::render(FrameRequest request, std::chrono::milliseconds timeout) {
  if (request.width < 16 || request.width > 4096 || request.height < 16 || request.height > 4096)
    throw unprocessable("width", "width and height must be 16 to 4096 pixels, found " + std::to_string(request.width) +
                                     "x" + std::to_string(request.height));
  if (request.format != "jpeg" && request.format != "png") throw unprocessable("format", "expected jpeg or png");
  if (request.quality < 1 || request.quality > 100) throw unprocessable("quality", "expected 1 to 100");
  auto task = std::make_shared<Task>();
  task->request = std::move(request);
  std::future<EncodedFrame> result = task->result.get_future();
  {
    std::lock_guard lock(mutex_);
    if (!available_) throw ApiError(503, "rendering_off", status_);
    if (stopping_) throw ApiError(503, "shutting_down", "the server is stopping");
    if (tasks_.size() >= 64) throw ApiError(503, "render_busy", "64 frames are waiting to be drawn; retry later");
    tasks_.push_back(task);
  }
  wake_.notify_one();
  if (result.wait_for(timeout) != std::future_status::ready)
    throw ApiError(503, "render_timeout", "the frame was not drawn within " + std::to_string(timeout.count()) + " ms");
  return result.get();
}

}  // namespace levelset::service
