// SseParser: Server-Sent Events (text/event-stream) decoded incrementally from arbitrary byte
// chunks: "id:", "event:", "data:" fields (several data lines joined with "\n"), comments
// (":" lines, the server's keep-alives), LF or CRLF line ends; a blank line ends an event.
#pragma once

#include <functional>
#include <string>
#include <string_view>

namespace levelset::client {

struct SseEvent {
  std::string id;    // the event's id (empty when it had none)
  std::string type = "message";
  std::string data;
};

class SseParser {
 public:
  // Feeds bytes; calls on_event for each complete event. Returns false when on_event did.
  bool feed(std::string_view bytes, const std::function<bool(const SseEvent&)>& on_event);

 private:
  bool line(std::string_view text, const std::function<bool(const SseEvent&)>& on_event);
  std::string pending_;  // an incomplete line
  SseEvent event_;
  bool has_data_ = false;
};

}  // namespace levelset::client
