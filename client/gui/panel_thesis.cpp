// Thesis table 4.1, A-L: the GLUI panel of the thesis's viewer as ImGui controls.
#include "panels.hpp"

namespace levelset::gui {

namespace {

void section(const char* title) {
  ImGui::Spacing();
  ImGui::TextColored(ImVec4(0.55f, 0.8f, 1.0f, 1.0f), "%s", title);
  ImGui::Separator();
}

void mesh_sections(PanelContext& c) {
  PanelState& p = c.s.panel;
  section("C  Load and save mesh");
  ui::text("mesh file", "path of an .off .ply .obj .stl", &p.mesh_file);
  if (ui::button("Load mesh")) c.a.load_mesh();
  ImGui::SameLine();
  ImGui::TextDisabled("%s", c.s.mesh_upload.empty() ? "(not loaded)" : c.s.mesh_upload.c_str());
  ui::text("save as", &p.save_file);
  if (ui::button("Save mesh")) c.a.save_mesh();

  section("B  Compute distance field");
  ImGui::SliderFloat("band width (voxels)", &p.band, 1.0f, 10.0f, "%.1f");
  ImGui::SliderInt("resolution", &p.resolution, 16, 512);
  ui::checkbox("ROI", &p.roi);
  ImGui::SameLine();
  ImGui::TextDisabled(p.roi ? "(the field becomes the shown session's roi)" : "(store the field for formulas' roi)");
  if (ui::button("Compute distance field")) c.a.compute_distance();
  ImGui::SameLine();
  ImGui::TextDisabled("(closest point transform)");
  // The shown session's region of influence: what formulas read as roi.
  const nlohmann::json& roi = c.s.session.is_object() ? c.s.session.value("roi", nlohmann::json()) : nlohmann::json();
  if (ui::button("Store field as ROI")) c.a.store_roi();
  ImGui::SameLine();
  if (ui::button("Clear ROI")) c.a.clear_roi();
  if (roi.is_object()) {
    const std::string from = roi.contains("session") ? "session " + roi.value("session", "")
                             : roi.contains("snapshot") ? "snapshot " + roi.value("snapshot", "")
                                                        : "version " + std::to_string(roi.value("version", 0));
    ImGui::TextDisabled("roi: %s, %llu voxels", from.c_str(), (unsigned long long)roi.value("active_voxels", 0ull));
  } else {
    ImGui::TextDisabled("roi: none");
  }
}

void evolution_sections(PanelContext& c) {
  PanelState& p = c.s.panel;
  section("G  Surface evolution");
  draw_formula_box(c);
  ImGui::Checkbox("by time", &p.use_time);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(110);
  if (p.use_time) {
    ImGui::InputFloat("time", &p.time, 0, 0, "%.4g");
  } else {
    ImGui::InputInt("steps", &p.steps);
    p.steps = std::max(1, p.steps);
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(100);
  ImGui::Combo("scheme", &p.scheme, "godunov\0eno2\0weno5\0");
  if (ui::button("Evolve")) c.a.evolve();
  ImGui::SameLine();
  if (ui::button("Stop")) c.a.stop_evolution();
  // The shown session's running job, as in the Jobs tab (its events feed the bar).
  for (const JobRow& j : c.s.jobs)
    if (j.session == c.s.current && (j.state == "running" || j.state == "queued")) {
      ImGui::SameLine();
      ImGui::ProgressBar(float(j.fraction), ImVec2(-1, 0), (j.op + " " + j.state).c_str());
      break;
    }

  section("H  Correct distance field");
  if (ui::button("Redistance")) c.a.redistance();

  section("F  Isosurface extraction");
  ImGui::SetNextItemWidth(150);
  ImGui::InputFloat("iso value", &p.iso, 0, 0, "%.4g");
  ImGui::SameLine();
  if (ui::button("Extract")) c.a.extract();
}

void display_sections(PanelContext& c) {
  PanelState& p = c.s.panel;
  section("A  Mesh shading");
  const char* shadings[] = {"none", "points", "wireframe", "flat", "smooth"};
  for (int i = 0; i < 5; ++i) {
    if (i > 0) ImGui::SameLine();
    ui::radio(shadings[i], &p.shading, i);
  }
  section("D  Distance field shading");
  // Thesis order: None, Point, Distance (vectors), Curve, Point(ROI), Boundary (PanelState::field's
  // numbers keep the order they were added in: ROI is 5).
  const char* fields[] = {"none##field", "points##field", "vectors", "curvature", "ROI##field", "boundary"};
  const int values[] = {0, 1, 2, 3, 5, 4};
  for (int i = 0; i < 6; ++i) {
    if (i > 0 && i != 4) ImGui::SameLine();  // two rows: the panel is 420 px wide
    ui::radio(fields[i], &p.field, values[i]);
  }
  section("E  Show range");
  ui::checkbox("whole band", &p.whole_range);
  if (!p.whole_range) ImGui::DragFloatRange2("distance range", &p.range_min, &p.range_max, 0.001f, -10.0f, 10.0f, "%.4f");
  section("I  Point cloud shading");
  ui::radio("none##cloud", &p.cloud, 0);
  ImGui::SameLine();
  ui::radio("points##cloud", &p.cloud, 1);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(120);
  ImGui::SliderFloat("size", &p.cloud_size, 1.0f, 16.0f, "%.0f px");
}

void file_sections(PanelContext& c) {
  PanelState& p = c.s.panel;
  section("J  Load point cloud");
  ui::text("points file", "path of an .xyz .pwn .ply", &p.points_file);
  if (ui::button("Load point cloud")) c.a.load_points();
  ImGui::SameLine();
  if (ui::button("Reconstruct")) c.a.reconstruct();
  section("K  Screenshot   L  Quit");
  ui::text("PNG file", &p.screenshot_file);
  if (ui::button("Screenshot")) c.a.request_screenshot();
  ImGui::SameLine();
  if (ui::button("Quit")) c.a.quit();
}

}  // namespace

void draw_formula_box(PanelContext& c) {
  PanelState& p = c.s.panel;
  ImGui::SetNextItemWidth(-1);
  ui::text("##formula", &p.formula);
  const FormulaError& fe = c.s.formula_error;
  if (fe.column <= 0 || fe.formula != p.formula) return;
  // The caret under the server's column: the box's text starts at FramePadding.x, and the
  // default font is fixed-width, so the prefix's width is the column's offset.
  const ImVec2 box = ImGui::GetItemRectMin();
  const std::size_t prefix = std::min(std::size_t(fe.column - 1), fe.formula.size());
  const float x = box.x + ImGui::GetStyle().FramePadding.x + ImGui::CalcTextSize(fe.formula.substr(0, prefix).c_str()).x;
  ImGui::SetCursorScreenPos(ImVec2(x, ImGui::GetCursorScreenPos().y));
  ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "^");
  ImGui::PushTextWrapPos(0);
  ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "column %d: %s", fe.column, fe.message.c_str());
  ImGui::PopTextWrapPos();
}

void draw_thesis_controls(PanelContext& c) {
  mesh_sections(c);
  evolution_sections(c);
  display_sections(c);
  file_sections(c);
}

}  // namespace levelset::gui
