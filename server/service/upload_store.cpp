#include "service/upload_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "grid/lsg_file.hpp"
#include "io/image_reader.hpp"
#include "io/mesh_reader.hpp"
#include "io/ply_parser.hpp"
#include "io/point_cloud_reader.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"

namespace levelset::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormats[] = {"off", "ply", "obj", "stl", "tria", "xyz", "xyzn", "pwn", "inr", "nrrd", "lsg"};

json bounds_json(const BBox& b) {
  if (b.empty()) return nullptr;
  return {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
}

// Reads the file with the strict reader of its format: the kind and a summary, or Error.
json validate(const fs::path& path, const std::string& format) {
  if (format == "lsg") {
    const LsgReadResult r = load_lsg(path);
    return {{"kind", "band"},
            {"summary", {{"active_voxels", r.band.active_voxel_count()}, {"voxel_size", r.band.voxel_size()},
                         {"half_width_voxels", r.band.half_width()}}}};
  }
  if (format == "inr" || format == "nrrd") {
    ImageReadOptions o;
    o.allow_infinite = true;
    const ImageReadResult r = read_image(path, o);
    return {{"kind", "image"},
            {"summary", {{"dims", {r.image.nx, r.image.ny, r.image.nz}}, {"sample_type", r.sample_type},
                         {"bounds", bounds_json(r.image.bounds())}}}};
  }
  bool points = format == "xyz" || format == "xyzn" || format == "pwn";
  if (format == "ply") {
    const std::string bytes = read_file_bytes(path, MeshReadOptions{}.max_file_bytes);
    points = ply::parse_header(bytes, path.filename().string()).find("face") == nullptr;
  }
  if (points) {
    const PointCloudReadResult r = read_point_cloud(path);
    return {{"kind", "points"},
            {"summary", {{"points", r.cloud.points.size()}, {"normals", r.cloud.has_normals()},
                         {"bounds", bounds_json(r.cloud.bounds())}}}};
  }
  const MeshReadResult r = read_mesh(path);
  return {{"kind", "mesh"},
          {"summary", {{"vertices", r.mesh.vertices.size()}, {"triangles", r.mesh.triangles.size()},
                       {"bounds", bounds_json(r.mesh.bounds())}}}};
}

json read_meta(const fs::path& path) {
  const std::string bytes = read_file_bytes(path, 1 << 20);
  json j = json::parse(bytes, nullptr, false);
  if (j.is_discarded()) throw Error(ErrorCode::Corrupt, path.string(), "not JSON");
  return j;
}

}  // namespace

bool UploadStore::known_format(const std::string& format) {
  for (const char* f : kFormats)
    if (format == f) return true;
  return false;
}

UploadStore::UploadStore(fs::path dir, std::uint64_t max_upload_bytes, std::uint64_t max_total_bytes)
    : dir_(std::move(dir)), max_upload_(max_upload_bytes), max_total_(max_total_bytes) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw Error(ErrorCode::IoError, dir_.string(), "cannot create the uploads directory: " + ec.message());
  for (const fs::directory_entry& e : fs::directory_iterator(dir_, ec))
    if (e.path().filename().string().find(".part-") != std::string::npos) fs::remove(e.path(), ec);
}

UploadStore::Writer::~Writer() {
  if (fd_ >= 0) ::close(fd_);
  std::error_code ec;
  if (!temp_.empty()) fs::remove(temp_, ec);
}

bool UploadStore::Writer::write(const char* data, std::size_t size) {
  if (over_ || failed_) return false;
  if (bytes_ + size > limit_) {
    over_ = true;
    return false;
  }
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      failed_ = true;
      return false;
    }
    done += std::size_t(n);
  }
  bytes_ += size;
  return true;
}

std::unique_ptr<UploadStore::Writer> UploadStore::begin(const std::string& replica, const std::string& format) {
  if (!known_format(format))
    throw ApiError(415, "unsupported_format",
                   "unknown upload format '" + format.substr(0, 20) +
                       "' (known: off ply obj stl tria xyz xyzn pwn inr nrrd lsg)");
  const std::uint64_t used = total_bytes();
  if (used >= max_total_)
    throw ApiError(507, "limit_exceeded", "uploads take " + std::to_string(used) + " bytes, the limit (max_uploads_total)");
  auto w = std::make_unique<Writer>();
  w->id_ = new_id(replica, 'u') + "." + format;
  w->format_ = format;
  w->final_ = dir_ / w->id_;
  w->temp_ = dir_ / (w->id_ + ".part-" + std::to_string(::getpid()));
  w->limit_ = std::min(max_upload_, max_total_ - used);
  w->fd_ = ::open(w->temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (w->fd_ < 0) throw Error(ErrorCode::IoError, w->temp_.string(), std::string("cannot create: ") + std::strerror(errno));
  return w;
}

json UploadStore::finish(Writer& w) {
  if (w.over_) throw ApiError(413, "payload_too_large", "the upload exceeds " + std::to_string(w.limit_) + " bytes (max_upload_bytes)");
  if (w.failed_ || ::fsync(w.fd_) != 0 || ::close(w.fd_) != 0) {
    w.fd_ = -1;
    throw ApiError(507, "io_error", "cannot store the upload (disk full?)");
  }
  w.fd_ = -1;
  // The readers pick the format by extension: validate under a name with the right one.
  const fs::path named = dir_ / (w.id_ + ".part-" + std::to_string(::getpid()) + "." + w.format_);
  fs::rename(w.temp_, named);
  w.temp_ = named;
  json j;
  try {
    j = validate(named, w.format_);
  } catch (const Error& e) {
    // The place names the upload id, not the temporary file the readers saw.
    std::string at = e.where().substr(e.where().rfind('/') + 1);
    if (at.rfind(named.filename().string(), 0) == 0) at = w.id_ + at.substr(named.filename().string().size());
    throw ApiError::from_error(Error(e.code(), "upload (" + w.format_ + ")", e.reason() + " [at " + at + "]"));
  }
  j["id"] = w.id_;
  j["format"] = w.format_;
  j["bytes"] = w.bytes_;
  j["created"] = now_iso();
  write_file_atomically(dir_ / (w.id_ + ".json"), j.dump());
  fs::rename(named, w.final_);
  w.temp_.clear();
  return j;
}

json UploadStore::get(const std::string& id) const {
  if (!is_valid_id(id, 'u')) throw not_found("upload", id);
  std::error_code ec;
  if (!fs::exists(dir_ / id, ec)) throw not_found("upload", id);
  return read_meta(dir_ / (id + ".json"));
}

fs::path UploadStore::path_of(const std::string& id) const {
  get(id);
  return dir_ / id;
}

void UploadStore::remove(const std::string& id) {
  get(id);
  std::error_code ec;
  fs::remove(dir_ / id, ec);
  fs::remove(dir_ / (id + ".json"), ec);
}

json UploadStore::list() const {
  json out = json::array();
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir_, ec)) {
    const std::string name = e.path().filename().string();
    if (is_valid_id(name, 'u')) {
      try {
        out.push_back(read_meta(dir_ / (name + ".json")));
      } catch (const Error&) {
      }
    }
  }
  return out;
}

std::uint64_t UploadStore::total_bytes() const {
  std::uint64_t total = 0;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir_, ec))
    if (e.is_regular_file(ec)) total += e.file_size(ec);
  return total;
}

}  // namespace levelset::service
