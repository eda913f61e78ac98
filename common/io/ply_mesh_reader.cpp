// PLY meshes (ascii, binary little / big endian): the vertex and face elements of a PLY file.
#include "io/mesh_format_readers.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "io/ply_parser.hpp"

namespace levelset::detail {

void read_ply(Reader& r) {
  const ply::Header h = ply::parse_header(r.bytes, r.name);
  switch (h.encoding) {
    case ply::Encoding::Ascii:
      r.result.format = MeshFormat::PlyAscii;
      break;
    case ply::Encoding::BinaryLittleEndian:
      r.result.format = MeshFormat::PlyBinaryLittleEndian;
      break;
    case ply::Encoding::BinaryBigEndian:
      r.result.format = MeshFormat::PlyBinaryBigEndian;
      break;
  }
  const ply::Element* vertex = h.find("vertex");
  const ply::Element* face = h.find("face");
  if (vertex == nullptr)
    throw Error(ErrorCode::ParseError, at_line(r.name, h.body_line - 1),
                "the PLY header declares no 'vertex' element");
  if (face == nullptr)
    throw Error(ErrorCode::ParseError, at_line(r.name, h.body_line - 1),
                "the PLY header declares no 'face' element (a point cloud? read it with "
                "read_point_cloud)");
  int xyz[3];
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    xyz[a] = vertex->find(axes[a]);
    if (xyz[a] < 0 || vertex->properties[static_cast<std::size_t>(xyz[a])].is_list)
      throw Error(ErrorCode::ParseError, at_line(r.name, vertex->line),
                  std::string("the 'vertex' element has no scalar property '") + axes[a] + "'");
  }
  int indices = face->find("vertex_indices");
  if (indices < 0) indices = face->find("vertex_index");
  if (indices < 0 || !face->properties[static_cast<std::size_t>(indices)].is_list)
    throw Error(ErrorCode::ParseError, at_line(r.name, face->line),
                "the 'face' element has no list property 'vertex_indices' or 'vertex_index'");
  if (!ply::is_integer(face->properties[static_cast<std::size_t>(indices)].type))
    throw Error(ErrorCode::UnsupportedFormat, at_line(r.name, face->line),
                "the face vertex indices must have an integer type");
  r.check_counts(vertex->count, 0, at_line(r.name, vertex->line), "faces");
  r.check_counts(0, face->count, at_line(r.name, face->line), "faces");
  ply::check_body_size(h, r.bytes, r.name);
  {
    // Every face lists at least 3 indices: a tighter bound than the generic one, before the
    // triangles are reserved.
    const ply::Property& list = face->properties[static_cast<std::size_t>(indices)];
    const std::uint64_t min_face =
        h.encoding == ply::Encoding::Ascii
            ? 2 * face->properties.size() + 6
            : ply::min_item_bytes(*face, h.encoding) + 3 * ply::type_size(list.type);
    const std::uint64_t available = r.bytes.size() - h.body_offset + 1;
    if (ply::saturating_mul(face->count, min_face) > available)
      throw Error(ErrorCode::Truncated, at_line(r.name, face->line),
                  "element 'face' claims " + std::to_string(face->count) +
                      " faces of at least 3 vertices, which need at least " +
                      std::to_string(min_face) + " bytes each, but only " +
                      std::to_string(available - 1) + " bytes follow the header");
  }

  auto& mesh = r.result.mesh;
  mesh.vertices.reserve(vertex->count);
  mesh.triangles.reserve(face->count);
  const std::uint64_t nv = vertex->count;
  ply::BodyReader body(h, r.bytes, r.name);
  const auto where_fn = [&] { return body.where(); };
  const auto fail_fn = [&](std::string reason) {
    body.fail(ErrorCode::ParseError, std::move(reason));
  };
  Fan fan;
  for (const ply::Element& e : h.elements) {
    const std::size_t np = e.properties.size();
    if (&e == vertex) {
      for (std::uint64_t i = 0; i < e.count; ++i) {
        Vec3d v;
        for (std::size_t p = 0; p < np; ++p) {
          const ply::Property& prop = e.properties[p];
          const int ip = static_cast<int>(p);
          if (ip == xyz[0] || ip == xyz[1] || ip == xyz[2]) {
            const double value = body.read_number(prop.type, "a vertex coordinate");
            if (!std::isfinite(value))
              body.fail(ErrorCode::NonFinite, "vertex " + std::to_string(i) + " has a non-finite " +
                                                  prop.name + " coordinate");
            v[ip == xyz[0] ? 0 : (ip == xyz[1] ? 1 : 2)] = value;
          } else {
            body.skip(prop);
          }
        }
        mesh.vertices.push_back(v);
        if (++r.records % kProgressEvery == 0) r.options.progress.step(body.fraction(), kStage);
      }
    } else if (&e == face) {
      for (std::uint64_t f = 0; f < e.count; ++f) {
        for (std::size_t p = 0; p < np; ++p) {
          const ply::Property& prop = e.properties[p];
          if (static_cast<int>(p) != indices) {
            body.skip(prop);
            continue;
          }
          const std::uint64_t n = body.read_list_count(prop, "the vertex count of a face");
          if (n < 3) fail_fn("a face needs at least 3 vertices, found " + std::to_string(n));
          for (std::uint64_t k = 0; k < n; ++k) {
            const std::int64_t index = body.read_integer(prop.type, "a vertex index");
            if (index < 0 || static_cast<std::uint64_t>(index) >= nv)
              body.fail(ErrorCode::ParseError, "vertex index " + std::to_string(index) +
                                                   " is out of range (the file has " +
                                                   std::to_string(nv) + " vertices)");
            fan.add(static_cast<std::uint32_t>(index), r, where_fn);
          }
          fan.finish(r, fail_fn);
        }
        if (++r.records % kProgressEvery == 0) r.options.progress.step(body.fraction(), kStage);
      }
    } else {
      for (std::uint64_t i = 0; i < e.count; ++i) {
        for (const ply::Property& prop : e.properties) body.skip(prop);
        if (++r.records % kProgressEvery == 0) r.options.progress.step(body.fraction(), kStage);
      }
    }
  }
  body.finish();
}

}  // namespace levelset::detail
