// The daemon's renderer from levelset_render: an offscreen context (EGL surfaceless or OSMesa)
// made on the render thread, the session's surface uploaded once per state, frames drawn with
// the session's view and the request's settings, encoded as JPEG or PNG.
#include "render/offscreen_context.hpp"
#include "render/scene_renderer.hpp"
#include "service/render_service.hpp"

namespace levelset::service {

namespace {

class GlSceneRenderer : public SceneRenderer {
 public:
  explicit GlSceneRenderer(render::ContextKind kind)
      : context_(render::create_offscreen_context(kind)), scene_(context_->gl()) {}

  std::string name() const override { return context_->renderer_name(); }

  void set_scene(std::shared_ptr<const NarrowBand> band, const TriangleMesh& surface,
                 std::shared_ptr<const PointCloud> points, std::shared_ptr<const NarrowBand> roi) override {
    scene_.set_scene(render::SceneData{surface, points ? *points : PointCloud{}, std::move(band), std::move(roi), nullptr});
  }

  EncodedFrame render(const nlohmann::json& view, const std::vector<std::pair<std::string, std::string>>& query, int width,
                      int height, const std::string& format, int quality) override {
    render::ViewSettings settings = render::from_json(view);
    for (const auto& [key, value] : query) render::apply_query(settings, key, value);
    settings.width = width;
    settings.height = height;
    const render::Image image = scene_.render(settings);
    EncodedFrame f;
    f.bytes = std::make_shared<const std::string>(format == "png" ? render::encode_png(image)
                                                                  : render::encode_jpeg(image, quality));
    f.content_type = format == "png" ? "image/png" : "image/jpeg";
    f.width = width;
    f.height = height;
    return f;
  }

 private:
  std::unique_ptr<render::OffscreenContext> context_;
  render::SceneRenderer scene_;
};

}  // namespace

void check_view_settings(const nlohmann::json& view) { (void)render::from_json(view); }

RendererFactory default_renderer_factory() {
  return [](const std::string& mode) -> std::unique_ptr<SceneRenderer> {
    return std::make_unique<GlSceneRenderer>(mode == "osmesa" ? render::ContextKind::OsMesa : render::ContextKind::Egl);
  };
}

}  // namespace levelset::service
