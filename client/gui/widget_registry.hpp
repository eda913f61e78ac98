// WidgetRegistry: the screen rectangle of every labelled control drawn this frame, so --script
// can click a control by its label through injected ImGui mouse input (and tests can find it).
// The ui:: helpers draw a control and note where it went.
#pragma once

#include <map>
#include <string>

#include <imgui.h>
#include <imgui_stdlib.h>

namespace levelset::gui {

struct WidgetRect {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

class WidgetRegistry {
 public:
  void begin_frame() { rects_.clear(); }
  void note(const std::string& label) {
    const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
    rects_[label] = {a.x, a.y, b.x, b.y};
  }
  const WidgetRect* find(const std::string& label) const {
    auto it = rects_.find(label);
    return it == rects_.end() ? nullptr : &it->second;
  }
  const std::map<std::string, WidgetRect>& all() const { return rects_; }

 private:
  std::map<std::string, WidgetRect> rects_;
};

namespace ui {
inline WidgetRegistry* registry = nullptr;  // set by the App for the frame

inline bool noted(bool result, const char* label) {
  if (registry != nullptr) registry->note(label);
  return result;
}
inline bool button(const char* label) { return noted(ImGui::Button(label), label); }
inline bool checkbox(const char* label, bool* v) { return noted(ImGui::Checkbox(label, v), label); }
inline bool radio(const char* label, int* v, int value) { return noted(ImGui::RadioButton(label, v, value), label); }
inline bool text(const char* label, std::string* s) { return noted(ImGui::InputText(label, s), label); }
inline bool text(const char* label, const char* hint, std::string* s) {
  return noted(ImGui::InputTextWithHint(label, hint, s), label);
}
}  // namespace ui

}  // namespace levelset::gui
