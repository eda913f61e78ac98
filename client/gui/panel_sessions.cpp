// Beyond the thesis: the server (URL, token), the session list (create from a primitive or an
// upload, rename, delete, snapshot, restore) and job files.
#include "panels.hpp"

namespace levelset::gui {

using nlohmann::json;

namespace {

void server_section(PanelContext& c) {
  ImGui::TextColored(c.s.connected ? ImVec4(0.4f, 0.9f, 0.4f, 1) : ImVec4(1, 0.5f, 0.3f, 1), "%s %s",
                     c.s.connected ? "connected to" : "not connected:", c.s.server.c_str());
  ui::text("server URL", &c.server_input);
  ImGui::InputText("token", &c.token_input, ImGuiInputTextFlags_Password);
  if (ui::button("Connect")) c.a.connect(c.server_input, c.token_input);
}

void session_rows(PanelContext& c) {
  if (!ImGui::BeginTable("sessions", 4, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY,
                         ImVec2(0, 180)))
    return;
  ImGui::TableSetupColumn("name");
  ImGui::TableSetupColumn("ver", ImGuiTableColumnFlags_WidthFixed, 30);
  ImGui::TableSetupColumn("voxels", ImGuiTableColumnFlags_WidthFixed, 70);
  ImGui::TableSetupColumn("", ImGuiTableColumnFlags_WidthFixed, 50);
  ImGui::TableHeadersRow();
  std::string select, remove;
  for (const json& s : c.s.sessions) {
    const std::string id = s.value("id", ""), name = s.value("name", id);
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    if (ImGui::Selectable((name + "##" + id).c_str(), id == c.s.current)) select = id;
    ImGui::TableNextColumn();
    ImGui::Text("%d", s.value("version", 0));
    ImGui::TableNextColumn();
    const json band = s.value("band", json::object());
    ImGui::Text("%.0fk", band.is_object() ? band.value("active_voxels", 0.0) / 1000 : 0.0);
    ImGui::TableNextColumn();
    if (ImGui::SmallButton(("delete##" + id).c_str())) remove = id;
  }
  ImGui::EndTable();
  if (!select.empty() && select != c.s.current) {
    c.a.select_session(select);
    c.a.refresh_snapshots();
  }
  if (!remove.empty()) c.a.delete_session(remove);
}

void current_session(PanelContext& c) {
  PanelState& p = c.s.panel;
  if (c.s.current.empty()) return;
  ImGui::Text("shown: %s (version %d)", c.s.session.is_object() ? c.s.session.value("name", c.s.current).c_str()
                                                                 : c.s.current.c_str(), c.s.version());
  ImGui::SetNextItemWidth(200);
  ui::text("##new_name", "new name", &p.new_name);
  ImGui::SameLine();
  if (ui::button("Rename")) c.a.rename_session();
  ImGui::SetNextItemWidth(200);
  ui::text("##snapshot_name", "snapshot name", &p.snapshot_name);
  ImGui::SameLine();
  if (ui::button("Snapshot")) c.a.snapshot();
  for (const json& snap : c.s.snapshots) {
    const std::string sid = snap.value("id", "");
    ImGui::BulletText("%s %s (version %d)", sid.c_str(), snap.value("name", "").c_str(), snap.value("version", 0));
    ImGui::SameLine();
    if (ImGui::SmallButton(("restore##" + sid).c_str())) c.a.restore(sid);
  }
}

}  // namespace

void draw_server_and_sessions(PanelContext& c) {
  PanelState& p = c.s.panel;
  server_section(c);
  ImGui::Separator();
  ImGui::Text("Sessions");
  session_rows(c);
  ImGui::SetNextItemWidth(120);
  const char* shapes[] = {"sphere", "box", "torus", "dumbbell", "knot"};
  int shape = 4;
  for (int i = 0; i < 5; ++i)
    if (p.primitive == shapes[i]) shape = i;
  if (ImGui::Combo("##primitive", &shape, shapes, 5)) p.primitive = shapes[shape];
  ImGui::SameLine();
  if (ui::button("New from primitive")) c.a.create_primitive();
  current_session(c);
  ImGui::Separator();
  ImGui::Text("Job file (as levelsetctl run)");
  ui::text("job file", "configs/jobs/offset_knot.conf", &p.job_file);
  if (ui::button("Run job file")) c.a.run_job_file();
}

}  // namespace levelset::gui
