// read_point_cloud: strict readers of point clouds (positions, optionally normals).
//
// Inputs: a file path, or the bytes of a file plus a name (used in messages and for the
// extension). Formats by extension, case-insensitive:
//   .xyz        "x y z" per line, or "x y z nx ny nz" (then read as point + normal)
//   .xyzn .pwn  "x y z nx ny nz" per line (CGAL's .pwn)
//   .ply        element vertex with x, y, z and optionally nx, ny, nz (all three or none), any
//               scalar types, ascii or binary; other properties and elements (faces) skipped
//   .off        the vertices of an OFF file (faces are validated, then ignored)
// '#' starts a comment in the text formats; blank lines are skipped; every data line of a file
// must have the same number of columns.
// Outputs: points in file order and units; normals (one per point) as written, not normalised
// (zero-length normals are kept), or empty when the file has none.
// Errors: levelset::Error. ParseError (malformed number, wrong or inconsistent column count,
// partial normals), Truncated (empty input, no points, or fewer bytes than the header's counts
// need), LimitExceeded (file size or point count above the options), NonFinite (NaN or Inf in a
// point or a normal), UnsupportedFormat (unknown extension or magic), IoError (read_point_cloud
// only), Cancelled. where = "name:line" for text, "name @ byte N" for binary PLY bodies.
// Cost: one pass over the bytes; O(file size) time and memory. Progress every 2^20 points.
// Threading: reentrant; no shared state.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>

#include "core/progress.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

enum class PointCloudFormat { Xyz, Xyzn, Pwn, Ply, Off };

std::string_view to_string(PointCloudFormat format);

struct PointCloudReadOptions {
  std::uint64_t max_file_bytes = 1ull << 32;
  std::uint64_t max_points = 1ull << 28;
  ProgressHook progress;
};

struct PointCloudReadResult {
  PointCloud cloud;
  PointCloudFormat format = PointCloudFormat::Xyz;
};

PointCloudReadResult read_point_cloud(const std::filesystem::path& path,
                                      const PointCloudReadOptions& options = {});

PointCloudReadResult read_point_cloud_from_memory(std::string_view bytes, std::string_view name,
                                                  const PointCloudReadOptions& options = {});

}  // namespace levelset
