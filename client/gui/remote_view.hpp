// RemoteView: the remote-frames view mode, for sessions too big to download. A thread reads the
// session's MJPEG stream (GET /sessions/{id}/stream, multipart/x-mixed-replace), decodes each
// JPEG part and keeps the newest; the UI thread uploads it to a texture and ImGui draws it
// behind the panel. The camera and display settings reach the server through PUT .../view
// (Actions::push_view), which the stream follows. A broken stream is reopened after a pause.
// Replacing a stream never waits: the old thread is told to stop and joined once it has ended.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "net_worker.hpp"
#include "render/image_codec.hpp"

namespace levelset::gui {

// Splits a multipart/x-mixed-replace byte stream into its parts' bodies (Content-Length framed).
class MultipartReader {
 public:
  // Appends bytes; returns every complete part's body.
  std::vector<std::string> feed(const char* data, std::size_t n);

 private:
  std::string buffer_;
};

class RemoteView {
 public:
  RemoteView(const ApiHolder& api, Inbox& inbox);
  ~RemoteView();

  // Streams `session` at w x h (restarts the stream when either changes); "" stops it.
  void show(const std::string& session, int w, int h);
  // UI thread: the newest frame not yet taken.
  std::optional<render::Image> take_frame();

 private:
  struct Stream {
    std::atomic<bool> stop{false}, done{false};
    std::thread thread;
  };
  void loop(Stream& self, std::string session, int w, int h);
  void reap();
  const ApiHolder& api_;
  Inbox& inbox_;
  std::string session_;
  int width_ = 0, height_ = 0;
  Stream* current_ = nullptr;
  std::vector<std::unique_ptr<Stream>> streams_;  // the current one and those still ending
  std::mutex mutex_;
  std::optional<render::Image> frame_;
};

}  // namespace levelset::gui
