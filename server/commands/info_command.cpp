// levelsetd info FILE [--json]: what a mesh, point cloud, 3D image or .lsg file holds.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "grid/lsg_file.hpp"
#include "core/file_io.hpp"
#include "io/image_reader.hpp"
#include "io/mesh_reader.hpp"
#include "io/ply_parser.hpp"
#include "io/point_cloud_reader.hpp"

namespace levelset::cli {

namespace {

using nlohmann::json;

json vec_json(const Vec3d& v) { return json::array({v.x, v.y, v.z}); }
json bbox_json(const BBox& b) {
  if (b.empty()) return nullptr;
  return json{{"min", vec_json(b.min)}, {"max", vec_json(b.max)}};
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// Streams and checks the whole payload but keeps only the bricks, never the values.
json lsg_info(const std::string& path) {
  const LsgSummary r = summarize_lsg_file(path);
  const LsgHeader& h = r.header;
  const IndexBox& ib = r.active_index_bounds;
  const auto world = [&](const Coord& c) {
    return h.frame.origin + Vec3d{double(c.x), double(c.y), double(c.z)} * h.frame.voxel_size;
  };
  json j;
  j["kind"] = "narrow_band";
  j["format"] = "lsg";
  j["version"] = h.version;
  j["value_type"] = "float32";
  j["voxel_size"] = h.frame.voxel_size;
  j["origin"] = vec_json(h.frame.origin);
  j["band_half_width_voxels"] = h.frame.half_width;
  j["band_half_width"] = static_cast<float>(h.frame.half_width * h.frame.voxel_size);
  j["far_inside"] = h.far_inside;
  j["closest_points"] = h.closest_points;
  j["bricks"] = h.bricks;
  j["active_voxels"] = h.active_voxels;
  j["memory_bytes"] = r.memory_bytes;
  j["bytes_per_active_voxel"] = h.active_voxels ? double(r.memory_bytes) / double(h.active_voxels) : 0.0;
  j["file_bytes"] = r.file_bytes;
  j["index_bounds"] = ib.empty() ? json(nullptr)
                                 : json{{"min", {ib.min.x, ib.min.y, ib.min.z}},
                                        {"max", {ib.max.x, ib.max.y, ib.max.z}}};
  BBox wb;
  if (!ib.empty()) {
    wb.extend(world(ib.min));
    wb.extend(world(ib.max));
  }
  j["world_bounds"] = bbox_json(wb);
  return j;
}

json mesh_info(const MeshReadResult& r) {
  json j;
  j["kind"] = "mesh";
  j["format"] = std::string(to_string(r.format));
  j["vertices"] = r.mesh.vertices.size();
  j["triangles"] = r.mesh.triangles.size();
  j["source_faces"] = r.source_faces;
  j["polygons_triangulated"] = r.polygons_triangulated;
  j["world_bounds"] = bbox_json(r.mesh.bounds());
  return j;
}

json cloud_info(const PointCloudReadResult& r) {
  json j;
  j["kind"] = "point_cloud";
  j["format"] = std::string(to_string(r.format));
  j["points"] = r.cloud.points.size();
  j["normals"] = r.cloud.has_normals();
  j["world_bounds"] = bbox_json(r.cloud.bounds());
  return j;
}

// Images up to this many voxels are also scanned (samples checked, range found) with O(1)
// memory; larger ones are described by their header alone: info's cost never follows a
// header's claim (a 255 KB .inr.gz can claim 262M voxels).
constexpr std::uint64_t kInfoScanVoxels = std::uint64_t{1} << 24;

json image_info(const std::string& path) {
  ImageReadOptions options;
  options.allow_infinite = true;  // cost grids and travel times hold +Inf
  options.samples = ImageSamples::Skip;
  ImageReadResult r = read_image(path, options);
  const bool scanned = r.image.voxel_count() <= kInfoScanVoxels;
  if (scanned) {
    options.samples = ImageSamples::Scan;
    r = read_image(path, options);
  }
  const ImageVolume& im = r.image;
  json j;
  j["kind"] = "image";
  j["format"] = std::string(to_string(r.format));
  j["sample_type"] = r.sample_type;
  j["gzip"] = r.gzip;
  j["dims"] = {im.nx, im.ny, im.nz};
  j["spacing"] = {im.spacing.x, im.spacing.y, im.spacing.z};
  j["origin"] = {im.origin.x, im.origin.y, im.origin.z};
  j["range"] = scanned ? json::array({r.min_sample, r.max_sample}) : json(nullptr);
  j["samples_scanned"] = scanned;
  j["world_bounds"] = bbox_json(im.bounds());
  return j;
}

void print_human(const std::string& path, const json& j) {
  auto vec = [](const json& v) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v[0].get<double>(), v[1].get<double>(),
                  v[2].get<double>());
    return std::string(buf);
  };
  std::printf("file:            %s\n", path.c_str());
  const std::string kind = j["kind"];
  if (kind == "narrow_band") {
    std::printf("kind:            narrow band (.lsg v%u, float32)\n", j["version"].get<unsigned>());
    std::printf("voxel size:      %.9g\n", j["voxel_size"].get<double>());
    std::printf("origin:          %s\n", vec(j["origin"]).c_str());
    std::printf("band:            %.6g voxels half-width (%.6g world)\n",
                j["band_half_width_voxels"].get<double>(), j["band_half_width"].get<double>());
    std::printf("bricks:          %llu\n", j["bricks"].get<unsigned long long>());
    std::printf("active voxels:   %llu\n", j["active_voxels"].get<unsigned long long>());
    std::printf("memory:          %s (%.2f B per active voxel)\n",
                human_bytes(j["memory_bytes"]).c_str(), j["bytes_per_active_voxel"].get<double>());
    std::printf("file size:       %s\n", human_bytes(j["file_bytes"]).c_str());
    if (j["closest_points"].get<bool>()) std::printf("fields:          closest surface point per voxel\n");
  } else if (kind == "mesh") {
    std::printf("kind:            triangle mesh (%s)\n", j["format"].get<std::string>().c_str());
    std::printf("vertices:        %llu\n", j["vertices"].get<unsigned long long>());
    std::printf("triangles:       %llu (from %llu faces)\n", j["triangles"].get<unsigned long long>(),
                j["source_faces"].get<unsigned long long>());
  } else if (kind == "image") {
    std::printf("kind:            3D image (%s%s, %s samples)\n", j["format"].get<std::string>().c_str(),
                j["gzip"].get<bool>() ? ", gzip" : "", j["sample_type"].get<std::string>().c_str());
    std::printf("dims:            %lld x %lld x %lld\n", j["dims"][0].get<long long>(), j["dims"][1].get<long long>(),
                j["dims"][2].get<long long>());
    std::printf("spacing:         %s\n", vec(j["spacing"]).c_str());
    std::printf("origin:          %s\n", vec(j["origin"]).c_str());
    if (j["range"].is_null())
      std::printf("range:           not scanned (more than %llu voxels: header only)\n",
                  static_cast<unsigned long long>(kInfoScanVoxels));
    else
      std::printf("range:           %.6g .. %.6g\n", j["range"][0].get<double>(), j["range"][1].get<double>());
  } else {
    std::printf("kind:            point cloud (%s)\n", j["format"].get<std::string>().c_str());
    std::printf("points:          %llu%s\n", j["points"].get<unsigned long long>(),
                j["normals"].get<bool>() ? " with normals" : "");
  }
  if (!j["world_bounds"].is_null())
    std::printf("bounds:          %s - %s\n", vec(j["world_bounds"]["min"]).c_str(),
                vec(j["world_bounds"]["max"]).c_str());
}

}  // namespace

int run_info(const InfoArgs& args) {
  const std::string ext = lower_extension(args.path);
  json j;
  if (ext == ".lsg") {
    j = lsg_info(args.path);
  } else if (ext == ".xyz" || ext == ".xyzn" || ext == ".pwn") {
    j = cloud_info(read_point_cloud(args.path));
  } else if (ext == ".ply") {
    // The header decides: a PLY with a face element is a mesh, read (and refused) exactly as
    // cpt reads it; one without is a point cloud.
    const std::string bytes = read_file_bytes(args.path, MeshReadOptions{}.max_file_bytes);
    if (ply::parse_header(bytes, args.path).find("face") != nullptr)
      j = mesh_info(read_mesh_from_memory(bytes, args.path));
    else
      j = cloud_info(read_point_cloud_from_memory(bytes, args.path));
  } else if (ext == ".off" || ext == ".tria" || ext == ".obj" || ext == ".stl") {
    j = mesh_info(read_mesh(args.path));
  } else if (ext == ".inr" || ext == ".nrrd" || ext == ".nhdr" || ext == ".gz") {
    j = image_info(args.path);
  } else {
    throw Error(ErrorCode::UnsupportedFormat, args.path,
                "unknown extension '" + ext + "' (known: .lsg .off .tria .ply .obj .stl .xyz .xyzn .pwn .inr .inr.gz .nrrd .nhdr)");
  }
  j["file"] = args.path;
  if (args.json) {
    std::cout << json_text(j) << "\n";
  } else {
    print_human(args.path, j);
  }
  return 0;
}

}  // namespace levelset::cli
