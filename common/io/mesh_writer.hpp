// write_mesh: writes a TriangleMesh as OFF, OBJ, PLY, STL or tria (format from the extension,
// case-insensitive).
//
// Inputs: the mesh (vertices in world units; indices < vertices.size()), the target path, and
// MeshWriteOptions::binary, which picks binary (default) or ascii for PLY and STL.
//   .ply   binary_little_endian (or ascii): vertex double x y z, face list uchar int (uint when
//          there are more than 2^31 - 1 vertices) vertex_indices: binary round trips bit-exact
//   .stl   binary (80-byte header, uint32 count, float32 normal + 3 vertices + uint16 0) or
//          ascii; STL has no shared vertices and stores float32 in binary, so a binary round
//          trip is exact only for float-representable coordinates, and reading welds equal
//          coordinates (unreferenced or duplicate vertices do not come back)
//   .off .obj .tria   ascii
// ASCII numbers are written with std::to_chars' shortest round-trip form, so reading them back
// gives the identical doubles.
// Output: the file, written through write_file_atomically (temp file + fsync + rename).
// Errors: levelset::Error. NonFinite (a NaN or Inf coordinate), InvalidArgument (an index out of
// range), LimitExceeded (STL: more than 2^32 - 1 triangles or a coordinate beyond the float
// range), UnsupportedFormat (unknown extension), IoError (cannot write).
// Cost: O(mesh size) time; the whole file is built in memory first.
// Threading: reentrant.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "io/triangle_mesh.hpp"

namespace levelset {

struct MeshWriteOptions {
  bool binary = true;  // PLY and STL
};

void write_mesh(const TriangleMesh& mesh, const std::filesystem::path& path,
                const MeshWriteOptions& options = {});

// The bytes write_mesh would write; name picks the format (by extension) and names errors.
std::string write_mesh_to_memory(const TriangleMesh& mesh, std::string_view name,
                                 const MeshWriteOptions& options = {});

}  // namespace levelset
