// What is drawn over the scene and the panel frame: the connection banner, the newest errors,
// the status line (session, version, view mode, triangles, frame rate), and the panel window
// holding the tabs.
#include <cstdio>
#include <functional>

#include "panels.hpp"

namespace levelset::gui {

void draw_view_controls(PanelContext& c) {
  PanelState& p = c.s.panel;
  ImGui::Text("View mode");
  ui::radio("auto", &p.view_mode, 0);
  ImGui::SameLine();
  ui::radio("local geometry", &p.view_mode, 1);
  ImGui::SameLine();
  ui::radio("remote frames", &p.view_mode, 2);
  ImGui::InputInt("triangle budget", &p.triangle_budget, 10000, 100000);
  p.triangle_budget = std::max(1, p.triangle_budget);
  ImGui::Separator();
  ImGui::Text("Slice and volume (the band)");
  ImGui::Combo("slice", &p.slice, "none\0x\0y\0z\0");
  ImGui::SliderFloat("slice position", &p.slice_position, 0.0f, 1.0f);
  ui::checkbox("volume rendering", &p.volume);
  ImGui::Separator();
  ImGui::TextWrapped("Camera: drag to orbit, wheel or +/- to zoom, arrows turn 5 degrees, Home resets; 1-5 pick "
                     "the shading (A); F12 screenshot (K), Ctrl+Q quit (L).");
}

void draw_panel(PanelContext& c, float height) {
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, height));
  ImGui::Begin("levelset", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  if (ImGui::BeginTabBar("tabs")) {
    // Each tab's header is noted as "tab:NAME" so a script can click it.
    const auto tab = [](const char* name, const std::function<void()>& body) {
      const bool open = ImGui::BeginTabItem(name);
      if (ui::registry != nullptr) ui::registry->note(std::string("tab:") + name);
      if (open) {
        body();
        ImGui::EndTabItem();
      }
    };
    tab("Controls", [&] { draw_thesis_controls(c); });
    tab("Sessions", [&] { draw_server_and_sessions(c); });
    tab("Jobs", [&] { draw_jobs_and_log(c); });
    tab("View", [&] { draw_view_controls(c); });
    ImGui::EndTabBar();
  }
  ImGui::End();
}

void draw_overlay(const AppState& s, float scene_x, float width) {
  ImGui::SetNextWindowPos(ImVec2(scene_x + 8, 8));
  // The scene's width less a margin; the height follows the lines (auto-resize).
  ImGui::SetNextWindowSizeConstraints(ImVec2(width - 16, 0), ImVec2(width - 16, 10000));
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::Begin("##overlay", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoFocusOnAppearing |
                   ImGuiWindowFlags_NoNav | ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::PushTextWrapPos(0);
  if (!s.banner.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.3f, 0.25f, 1));
    ImGui::TextWrapped("%s", s.banner.c_str());
    ImGui::PopStyleColor();
  }
  const std::size_t first = s.errors.size() > 3 ? s.errors.size() - 3 : 0;
  for (std::size_t i = first; i < s.errors.size(); ++i) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.75f, 0.3f, 1));
    ImGui::TextWrapped("%s", s.errors[i].c_str());
    ImGui::PopStyleColor();
  }
  char status[256], fps[32] = "-- fps";  // measured over the first second
  if (s.fps > 0) std::snprintf(fps, sizeof fps, "%.0f fps", s.fps);
  std::snprintf(status, sizeof status, "%s  version %d  |  %s  |  %llu triangles  |  %s",
                s.current.empty() ? "no session" : s.current.c_str(), s.version(),
                s.remote ? "remote frames" : "local geometry", static_cast<unsigned long long>(s.mesh_triangles), fps);
  ImGui::TextUnformatted(status);
  ImGui::PopTextWrapPos();
  ImGui::End();
}

}  // namespace levelset::gui
