// read_image: picks INR or NRRD by the file's first bytes (looking through gzip for INR).
#include "io/image_reader.hpp"

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "io/image_format_readers.hpp"

namespace levelset {

std::string_view to_string(ImageFormat format) {
  switch (format) {
    case ImageFormat::Inr: return "inr";
    case ImageFormat::Nrrd: return "nrrd";
  }
  return "?";
}

namespace {

ImageReadResult read_any(std::string_view bytes, std::string_view name, const ImageReadOptions& options,
                         const detail::DataFileLoader& loader) {
  if (bytes.size() > options.max_file_bytes)
    throw Error(ErrorCode::LimitExceeded, std::string(name),
                "file of " + std::to_string(bytes.size()) + " bytes exceeds the limit of " + std::to_string(options.max_file_bytes));
  if (bytes.empty()) throw Error(ErrorCode::Truncated, at_byte(name, 0), "empty file");
  ImageReadResult result;
  if (bytes.rfind("NRRD", 0) == 0) {
    result = detail::read_nrrd(bytes, name, options, loader);
  } else {
    const bool gzip = detail::is_gzip(bytes);
    detail::ByteStream stream(bytes, gzip, std::string(name));
    char magic[4] = {};
    const std::size_t got = stream.read(magic, sizeof magic);
    stream.unread(std::string_view(magic, got));
    if (std::string_view(magic, got) == "#INR") {
      result = detail::read_inr(stream, name, options);
      result.gzip = gzip;
    } else if (std::string_view(magic, got) == "NRRD") {
      throw Error(ErrorCode::UnsupportedFormat, std::string(name),
                  "gzip-compressed NRRD file: compress the data with 'encoding: gzip' instead");
    } else {
      throw Error(ErrorCode::UnsupportedFormat, at_byte(name, 0),
                  std::string("unknown image format (expected #INRIMAGE-4#{ or NRRD000N") + (gzip ? " inside gzip)" : ")"));
    }
    result.file_bytes = bytes.size();
  }
  return result;
}

}  // namespace

ImageReadResult read_image_from_memory(std::string_view bytes, std::string_view name, const ImageReadOptions& options) {
  return read_any(bytes, name, options, {});
}

ImageReadResult read_image(const std::filesystem::path& path, const ImageReadOptions& options) {
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  const std::filesystem::path folder = path.parent_path();
  const detail::DataFileLoader loader = [&](const std::string& file) {
    // The data file lies beside the header: a relative name without '..', so a header
    // cannot make the reader disclose files elsewhere.
    const std::filesystem::path f(file);
    if (f.has_root_path() || file.find("..") != std::string::npos)
      throw Error(ErrorCode::UnsupportedFormat, path.string(),
                  "detached data file '" + file + "' must be a relative name in the header's folder, without '..'");
    return read_file_bytes(folder / f, options.max_file_bytes);
  };
  return read_any(bytes, path.string(), options, loader);
}

}  // namespace levelset
