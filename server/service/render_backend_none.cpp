// Builds without levelset_render: no renderer; the frame routes answer 503 and say so.
#include "service/render_service.hpp"

namespace levelset::service {

RendererFactory default_renderer_factory() { return {}; }

void check_view_settings(const nlohmann::json&) {}

}  // namespace levelset::service
