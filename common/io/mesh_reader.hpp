// read_mesh: strict readers of triangle and polygon meshes into a TriangleMesh (a triangle
// soup with shared vertices; see common/io/README.md for why not OpenMesh's reader).
//
// Inputs: a file path, or the bytes of a file plus a name (used in messages and for the
// extension). Formats by extension, case-insensitive: .off (OFF, COFF, NOFF, CNOFF, ST..., and
// files without the keyword line; extra per-vertex and per-face values are skipped), .tria
// (the thesis format: 4, nv, nt, vertices, zero-based triangles), .ply (ascii,
// binary_little_endian, binary_big_endian), .obj (v and f; other statements ignored),
// .stl (ascii or binary, sniffed by the binary size rule 84 + 50 n == file size).
// Outputs: vertices in the file's units and order (STL: exactly equal coordinates welded into
// one vertex, in order of first use); every polygon fan-triangulated (v0, vk, vk+1) in file
// order. Zero-area and repeated-index triangles are kept as they are: the distance code copes
// and the mesh must be seen as it is.
// Errors: levelset::Error, never a crash or an allocation from an unchecked count.
//   ParseError        malformed token, face with < 3 vertices, index out of range, garbage
//   Truncated         empty input, or input ending before the header's counts are satisfied
//                     (also counts that the remaining bytes could not possibly hold)
//   LimitExceeded     file size or counts above MeshReadOptions, integers beyond 64 bits
//   NonFinite         NaN or Inf vertex coordinates
//   UnsupportedFormat unknown extension or magic, unknown PLY property type, 4OFF / nOFF,
//                     binary OFF
//   IoError           (read_mesh only) the file cannot be read
//   Cancelled         the progress hook's token fired
//   where = "name:line" for text input, "name @ byte N" for binary PLY bodies and binary STL.
// Cost: one pass over the bytes, O(file size) time and memory (plus the whole file in memory
// for read_mesh). The progress hook is stepped every 2^20 records.
// Threading: reentrant; no shared state.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>

#include "core/progress.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

enum class MeshFormat {
  Off,
  Tria,
  PlyAscii,
  PlyBinaryLittleEndian,
  PlyBinaryBigEndian,
  Obj,
  StlAscii,
  StlBinary
};

// "off", "tria", "ply_ascii", "ply_binary_little_endian", "ply_binary_big_endian", "obj",
// "stl_ascii", "stl_binary".
std::string_view to_string(MeshFormat format);

struct MeshReadOptions {
  std::uint64_t max_file_bytes = 1ull << 32;
  std::uint64_t max_vertices = 1ull << 28;   // vertices in the result (at most 2^32)
  std::uint64_t max_triangles = 1ull << 29;  // triangles in the result, after triangulation
  ProgressHook progress;
};

struct MeshReadResult {
  TriangleMesh mesh;
  MeshFormat format = MeshFormat::Off;
  std::uint64_t source_faces = 0;           // faces (or STL facets) in the file
  std::uint64_t polygons_triangulated = 0;  // faces with more than 3 vertices
};

MeshReadResult read_mesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

MeshReadResult read_mesh_from_memory(std::string_view bytes, std::string_view name,
                                     const MeshReadOptions& options = {});

}  // namespace levelset
