#include "io/mesh_reader.hpp"

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "io/mesh_format_readers.hpp"

namespace levelset {

std::string_view to_string(MeshFormat format) {
  switch (format) {
    case MeshFormat::Off:
      return "off";
    case MeshFormat::Tria:
      return "tria";
    case MeshFormat::PlyAscii:
      return "ply_ascii";
    case MeshFormat::PlyBinaryLittleEndian:
      return "ply_binary_little_endian";
    case MeshFormat::PlyBinaryBigEndian:
      return "ply_binary_big_endian";
    case MeshFormat::Obj:
      return "obj";
    case MeshFormat::StlAscii:
      return "stl_ascii";
    case MeshFormat::StlBinary:
      return "stl_binary";
  }
  return "unknown";
}

namespace {

using detail::iequals;
using detail::kStage;
using detail::load_le32;
using detail::Reader;

// Binary when the size matches 84 + 50 n (even if it starts with "solid"), else ascii when it
// starts with "solid", else binary (and the size check explains what is wrong).
bool stl_is_binary(std::string_view bytes) {
  if (bytes.size() >= 84 && 84 + 50 * std::uint64_t{load_le32(bytes.data() + 80)} == bytes.size())
    return true;
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return !(bytes.size() - i >= 5 && iequals(bytes.substr(i, 5), "solid"));
}

// ---- dispatch -----------------------------------------------------------------------------

enum class Kind { Off, Tria, Ply, Obj, Stl };

Kind kind_from_name(std::string_view name) {
  std::string ext = std::filesystem::path(std::string(name)).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".off") return Kind::Off;
  if (ext == ".tria") return Kind::Tria;
  if (ext == ".ply") return Kind::Ply;
  if (ext == ".obj") return Kind::Obj;
  if (ext == ".stl") return Kind::Stl;
  throw Error(ErrorCode::UnsupportedFormat, std::string(name),
              "unknown mesh extension '" + ext + "' (expected .off, .tria, .ply, .obj or .stl)");
}

}  // namespace

MeshReadResult read_mesh_from_memory(std::string_view bytes, std::string_view name,
                                     const MeshReadOptions& options) {
  const Kind kind = kind_from_name(name);
  if (bytes.size() > options.max_file_bytes)
    throw Error(ErrorCode::LimitExceeded, std::string(name),
                "the input is " + std::to_string(bytes.size()) + " bytes, the limit is " +
                    std::to_string(options.max_file_bytes));
  if (bytes.empty())
    throw Error(ErrorCode::Truncated, kind == Kind::Stl ? at_byte(name, 0) : at_line(name, 1),
                "the file is empty");
  Reader r(bytes, name, options);
  options.progress.check(kStage);
  switch (kind) {
    case Kind::Off:
      r.result.format = MeshFormat::Off;
      detail::read_off(r);
      break;
    case Kind::Tria:
      r.result.format = MeshFormat::Tria;
      detail::read_tria(r);
      break;
    case Kind::Ply:
      detail::read_ply(r);
      break;
    case Kind::Obj:
      r.result.format = MeshFormat::Obj;
      detail::read_obj(r);
      break;
    case Kind::Stl:
      if (stl_is_binary(bytes))
        detail::read_stl_binary(r);
      else
        detail::read_stl_ascii(r);
      break;
  }
  return std::move(r.result);
}

MeshReadResult read_mesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  kind_from_name(path.string());  // refuse unknown extensions before reading
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  return read_mesh_from_memory(bytes, path.string(), options);
}

}  // namespace levelset
