#include "io/mesh_writer.hpp"

#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/error.hpp"
#include "core/file_io.hpp"

namespace levelset {

namespace {

enum class Kind { Off, Obj, Ply, Stl, Tria };

Kind kind_from_name(std::string_view name) {
  std::string ext = std::filesystem::path(std::string(name)).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".off") return Kind::Off;
  if (ext == ".obj") return Kind::Obj;
  if (ext == ".ply") return Kind::Ply;
  if (ext == ".stl") return Kind::Stl;
  if (ext == ".tria") return Kind::Tria;
  throw Error(ErrorCode::UnsupportedFormat, std::string(name),
              "unknown mesh extension '" + ext + "' (expected .off, .obj, .ply, .stl or .tria)");
}

void validate(const TriangleMesh& mesh, std::string_view name) {
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!isfinite(mesh.vertices[i]))
      throw Error(ErrorCode::NonFinite, std::string(name),
                  "vertex " + std::to_string(i) + " has a non-finite coordinate");
  const std::size_t nv = mesh.vertices.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (const std::uint32_t index : mesh.triangles[t])
      if (index >= nv)
        throw Error(ErrorCode::InvalidArgument, std::string(name),
                    "triangle " + std::to_string(t) + " refers to vertex " + std::to_string(index) +
                        " but the mesh has " + std::to_string(nv) + " vertices");
}

// Text output with shortest round-trip numbers.
struct Text {
  std::string out;

  Text& operator<<(std::string_view s) {
    out += s;
    return *this;
  }
  Text& operator<<(char c) {
    out += c;
    return *this;
  }
  template <typename T>
  requires std::is_arithmetic_v<T> Text& operator<<(T value) {
    char buffer[64];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, static_cast<std::size_t>(end - buffer));
    return *this;
  }
  void vec(const Vec3d& v) { *this << v.x << ' ' << v.y << ' ' << v.z; }
};

template <typename T>
void append_le(std::string& out, T value) {
  using U = std::conditional_t<
      sizeof(T) == 1, std::uint8_t,
      std::conditional_t<sizeof(T) == 2, std::uint16_t,
                         std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
  U u = std::bit_cast<U>(value);
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out += static_cast<char>(u & 0xff);
    u = static_cast<U>(u >> 8);
  }
}

std::string write_off(const TriangleMesh& mesh) {
  Text t;
  t.out.reserve(64 + mesh.vertices.size() * 60 + mesh.triangles.size() * 24);
  t << "OFF\n" << mesh.vertices.size() << ' ' << mesh.triangles.size() << " 0\n";
  for (const Vec3d& v : mesh.vertices) {
    t.vec(v);
    t << '\n';
  }
  for (const auto& tri : mesh.triangles)
    t << "3 " << tri[0] << ' ' << tri[1] << ' ' << tri[2] << '\n';
  return std::move(t.out);
}

std::string write_tria(const TriangleMesh& mesh) {
  Text t;
  t.out.reserve(64 + mesh.vertices.size() * 60 + mesh.triangles.size() * 24);
  t << "4\n" << mesh.vertices.size() << '\n' << mesh.triangles.size() << '\n';
  for (const Vec3d& v : mesh.vertices) {
    t.vec(v);
    t << '\n';
  }
  for (const auto& tri : mesh.triangles) t << tri[0] << ' ' << tri[1] << ' ' << tri[2] << '\n';
  return std::move(t.out);
}

std::string write_obj(const TriangleMesh& mesh) {
  Text t;
  t.out.reserve(64 + mesh.vertices.size() * 62 + mesh.triangles.size() * 26);
  t << "# written by levelset\n";
  for (const Vec3d& v : mesh.vertices) {
    t << "v ";
    t.vec(v);
    t << '\n';
  }
  for (const auto& tri : mesh.triangles)
    t << "f " << std::uint64_t{tri[0]} + 1 << ' ' << std::uint64_t{tri[1]} + 1 << ' '
      << std::uint64_t{tri[2]} + 1 << '\n';
  return std::move(t.out);
}

std::string write_ply(const TriangleMesh& mesh, bool binary) {
  const bool wide = mesh.vertices.size() > static_cast<std::size_t>(INT32_MAX);
  Text t;
  t << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
    << "comment written by levelset\n"
    << "element vertex " << mesh.vertices.size() << '\n'
    << "property double x\nproperty double y\nproperty double z\n"
    << "element face " << mesh.triangles.size() << '\n'
    << "property list uchar " << (wide ? "uint" : "int") << " vertex_indices\n"
    << "end_header\n";
  if (binary) {
    t.out.reserve(t.out.size() + mesh.vertices.size() * 24 + mesh.triangles.size() * 13);
    for (const Vec3d& v : mesh.vertices) {
      append_le(t.out, v.x);
      append_le(t.out, v.y);
      append_le(t.out, v.z);
    }
    for (const auto& tri : mesh.triangles) {
      t.out += static_cast<char>(3);
      for (const std::uint32_t index : tri) append_le(t.out, index);
    }
  } else {
    t.out.reserve(t.out.size() + mesh.vertices.size() * 60 + mesh.triangles.size() * 24);
    for (const Vec3d& v : mesh.vertices) {
      t.vec(v);
      t << '\n';
    }
    for (const auto& tri : mesh.triangles)
      t << "3 " << tri[0] << ' ' << tri[1] << ' ' << tri[2] << '\n';
  }
  return std::move(t.out);
}

Vec3d unit_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d n = cross(b - a, c - a);
  const double len = length(n);
  return len > 0 && std::isfinite(len) ? n / len : Vec3d{};
}

std::string write_stl(const TriangleMesh& mesh, bool binary, std::string_view name) {
  if (binary) {
    if (mesh.triangles.size() > UINT32_MAX)
      throw Error(ErrorCode::LimitExceeded, std::string(name),
                  "binary STL holds at most 2^32 - 1 triangles, the mesh has " +
                      std::to_string(mesh.triangles.size()));
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Vec3d& v = mesh.vertices[i];
      if (std::abs(v.x) > kFloatMax || std::abs(v.y) > kFloatMax || std::abs(v.z) > kFloatMax)
        throw Error(ErrorCode::LimitExceeded, std::string(name),
                    "vertex " + std::to_string(i) + " is beyond the float range of binary STL");
    }
  }
  if (!binary) {
    Text t;
    t.out.reserve(32 + mesh.triangles.size() * 300);
    t << "solid levelset\n";
    for (const auto& tri : mesh.triangles) {
      const Vec3d& a = mesh.vertices[tri[0]];
      const Vec3d& b = mesh.vertices[tri[1]];
      const Vec3d& c = mesh.vertices[tri[2]];
      t << "facet normal ";
      t.vec(unit_normal(a, b, c));
      t << "\n  outer loop\n";
      for (const Vec3d* v : {&a, &b, &c}) {
        t << "    vertex ";
        t.vec(*v);
        t << '\n';
      }
      t << "  endloop\nendfacet\n";
    }
    t << "endsolid levelset\n";
    return std::move(t.out);
  }
  std::string out;
  out.reserve(84 + 50 * mesh.triangles.size());
  std::string header = "binary STL written by levelset";
  header.resize(80, ' ');
  out += header;
  append_le(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const auto& tri : mesh.triangles) {
    const Vec3d& a = mesh.vertices[tri[0]];
    const Vec3d& b = mesh.vertices[tri[1]];
    const Vec3d& c = mesh.vertices[tri[2]];
    const Vec3d n = unit_normal(a, b, c);
    for (const Vec3d* v : {&n, &a, &b, &c}) {
      append_le(out, static_cast<float>(v->x));
      append_le(out, static_cast<float>(v->y));
      append_le(out, static_cast<float>(v->z));
    }
    append_le(out, std::uint16_t{0});
  }
  return out;
}

}  // namespace

std::string write_mesh_to_memory(const TriangleMesh& mesh, std::string_view name,
                                 const MeshWriteOptions& options) {
  const Kind kind = kind_from_name(name);
  validate(mesh, name);
  switch (kind) {
    case Kind::Off:
      return write_off(mesh);
    case Kind::Obj:
      return write_obj(mesh);
    case Kind::Ply:
      return write_ply(mesh, options.binary);
    case Kind::Stl:
      return write_stl(mesh, options.binary, name);
    case Kind::Tria:
      return write_tria(mesh);
  }
  return {};
}

void write_mesh(const TriangleMesh& mesh, const std::filesystem::path& path,
                const MeshWriteOptions& options) {
  write_file_atomically(path, write_mesh_to_memory(mesh, path.string(), options));
}

}  // namespace levelset
