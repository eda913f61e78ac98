// Uploads: files sent as raw request bodies, streamed to DATA/uploads/ under a size limit and
// validated by the strict readers before they are kept. The server names every file
// (<replica>-u-<hex>.<format>); no client path reaches the filesystem.
//
// Formats: meshes off ply obj stl tria; point clouds xyz xyzn pwn (and ply without faces);
// images inr nrrd (inr.gz: format inr, gzip detected); bands lsg.
// Flow: begin() checks the format and the total budget and opens a temp file; Writer::write()
// appends (false past the limit: 413); finish() validates, renames and records
// <id>.json (format, bytes, kind, summary); a failed validation removes the file (400/415).
// Threading: all members thread-safe; a Writer belongs to one request.
#pragma once

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

namespace levelset::service {

class UploadStore {
 public:
  UploadStore(std::filesystem::path dir, std::uint64_t max_upload_bytes, std::uint64_t max_total_bytes);

  class Writer {
   public:
    ~Writer();
    bool write(const char* data, std::size_t size);  // false: over the size limit
    bool over_limit() const { return over_; }

   private:
    friend class UploadStore;
    int fd_ = -1;
    std::filesystem::path temp_, final_;
    std::string id_, format_;
    std::uint64_t bytes_ = 0, limit_ = 0;
    bool over_ = false, failed_ = false;
  };

  std::unique_ptr<Writer> begin(const std::string& replica, const std::string& format);
  nlohmann::json finish(Writer& w);  // 201 body: id, format, bytes, kind, summary

  nlohmann::json get(const std::string& id) const;  // ApiError 404
  std::filesystem::path path_of(const std::string& id) const;
  void remove(const std::string& id);
  nlohmann::json list() const;
  const std::filesystem::path& dir() const { return dir_; }
  std::uint64_t total_bytes() const;

  static bool known_format(const std::string& format);

 private:
  std::filesystem::path dir_;
  std::uint64_t max_upload_, max_total_;
  mutable std::mutex mutex_;
};

}  // namespace levelset::service
