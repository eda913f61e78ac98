// Beyond the thesis: the job list with progress bars (fed by the jobs' event streams), cancel
// and stop, and the live log (job log lines, connection notices, errors).
#include "panels.hpp"

namespace levelset::gui {

void draw_jobs_and_log(PanelContext& c) {
  ImGui::Text("Jobs");
  if (ImGui::BeginTable("jobs", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY, ImVec2(0, 200))) {
    ImGui::TableSetupColumn("job", ImGuiTableColumnFlags_WidthFixed, 120);
    ImGui::TableSetupColumn("progress");
    ImGui::TableSetupColumn("", ImGuiTableColumnFlags_WidthFixed, 90);
    for (auto it = c.s.jobs.rbegin(); it != c.s.jobs.rend(); ++it) {
      const JobRow& j = *it;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%s %s", j.op.c_str(), j.id.size() > 8 ? j.id.substr(j.id.size() - 6).c_str() : j.id.c_str());
      ImGui::TableNextColumn();
      const std::string overlay = j.state + (j.stage.empty() || j.state != "running" ? "" : ": " + j.stage);
      ImGui::ProgressBar(float(j.fraction), ImVec2(-1, 0), overlay.c_str());
      ImGui::TableNextColumn();
      if (j.state == "running" || j.state == "queued") {
        if (ImGui::SmallButton(("cancel##" + j.id).c_str())) c.a.cancel_job(j.id);
        ImGui::SameLine();
        if (ImGui::SmallButton(("stop##" + j.id).c_str())) c.a.stop_job(j.id);
      }
    }
    ImGui::EndTable();
  }
  ImGui::Text("Log");
  if (ImGui::BeginChild("log", ImVec2(0, 0), true, ImGuiWindowFlags_HorizontalScrollbar)) {
    for (const std::string& line : c.s.log) ImGui::TextUnformatted(line.c_str());
    if (ImGui::GetScrollY() >= ImGui::GetScrollMaxY() - 20) ImGui::SetScrollHereY(1.0f);
  }
  ImGui::EndChild();
}

}  // namespace levelset::gui
