#include "remote_view.hpp"

#include <cstdlib>

#include "core/error.hpp"

namespace levelset::gui {

std::vector<std::string> MultipartReader::feed(const char* data, std::size_t n) {
  buffer_.append(data, n);
  std::vector<std::string> parts;
  for (;;) {
    const std::size_t length_at = buffer_.find("Content-Length:");
    if (length_at == std::string::npos) break;
    const std::size_t body_at = buffer_.find("\r\n\r\n", length_at);
    if (body_at == std::string::npos) break;
    const std::size_t length = std::strtoull(buffer_.c_str() + length_at + 15, nullptr, 10);
    if (buffer_.size() < body_at + 4 + length) break;
    parts.push_back(buffer_.substr(body_at + 4, length));
    buffer_.erase(0, body_at + 4 + length);
  }
  if (buffer_.size() > (64u << 20)) buffer_.clear();  // no framing found in 64 MiB: start over
  return parts;
}

RemoteView::RemoteView(const ApiHolder& api, Inbox& inbox) : api_(api), inbox_(inbox) {}

RemoteView::~RemoteView() {
  for (auto& s : streams_) s->stop = true;
  for (auto& s : streams_) s->thread.join();
}

void RemoteView::reap() {
  for (auto it = streams_.begin(); it != streams_.end();) {
    if ((*it)->done) {
      (*it)->thread.join();
      it = streams_.erase(it);
    } else {
      ++it;
    }
  }
}

void RemoteView::show(const std::string& session, int w, int h) {
  reap();
  if (session == session_ && w == width_ && h == height_) return;
  if (current_ != nullptr) current_->stop = true;
  current_ = nullptr;
  session_ = session;
  width_ = w;
  height_ = h;
  if (session.empty()) return;
  auto stream = std::make_unique<Stream>();
  Stream* raw = stream.get();
  raw->thread = std::thread([this, raw, session, w, h] {
    loop(*raw, session, w, h);
    raw->done = true;
  });
  current_ = raw;
  streams_.push_back(std::move(stream));
}

std::optional<render::Image> RemoteView::take_frame() {
  std::lock_guard lock(mutex_);
  std::optional<render::Image> out;
  out.swap(frame_);
  return out;
}

void RemoteView::loop(Stream& self, std::string session, int w, int h) {
  const std::string path = "/api/v1/sessions/" + client::Api::encode(session) + "/stream?width=" + std::to_string(w) +
                           "&height=" + std::to_string(h);
  while (!self.stop) {
    auto api = api_.get();
    MultipartReader reader;
    try {
      if (api) api->get_stream(path, nullptr, [&](const char* data, std::size_t n) {
        for (const std::string& part : reader.feed(data, n)) {
          render::Image image = render::decode_jpeg(part);
          std::lock_guard lock(mutex_);
          if (!self.stop) frame_ = std::move(image);
        }
        return !self.stop.load();
      });
    } catch (const std::exception& e) {
      inbox_.post([why = describe_error(e)](AppState& s) {
        if (s.connected) s.add_log("frame stream: " + why);
      });
    }
    sleep_unless(self.stop, 1.0);
  }
}

}  // namespace levelset::gui
