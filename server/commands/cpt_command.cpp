// levelsetd cpt MESH (--resolution R | --voxel-size H) --band W -o OUT.lsg: mesh -> band.
#include <chrono>
#include <cstdio>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/lsg_file.hpp"
#include "io/mesh_reader.hpp"

namespace levelset::cli {

int run_cpt(const CptArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const MeshReadResult read = read_mesh(args.mesh);
  const auto t1 = std::chrono::steady_clock::now();
  CptOptions options;
  if (args.voxel_size > 0) {
    const BBox box = read.mesh.bounds();
    if (box.empty()) throw Error(ErrorCode::InvalidArgument, args.mesh, "the mesh has no vertices");
    options.frame.voxel_size = args.voxel_size;
    options.frame.half_width = args.band;
    const double pad = args.band * args.voxel_size;
    options.frame.origin = box.min - Vec3d{pad, pad, pad};
  } else {
    options.frame = frame_for_resolution(read.mesh.bounds(), args.resolution, args.band);
  }
  options.closest_points = args.closest_points;
  options.method = args.method == "slab"             ? CptMethod::slab_scan
                   : args.method == "characteristic" ? CptMethod::characteristic
                                                     : CptMethod::automatic;
  const CptResult cpt = closest_point_transform(read.mesh, options);
  const auto t2 = std::chrono::steady_clock::now();
  LsgWriteOptions write_options;
  write_options.closest_points = cpt.closest_points;
  const LsgWriteResult written = save_lsg(cpt.band, args.output, write_options);
  const auto t3 = std::chrono::steady_clock::now();

  std::fprintf(summary_stream(args.stats), "%s: %zu triangles -> %zu active voxels in %zu bricks, voxel size %.6g, %.3f s -> %s (%s)\n",
              args.mesh.c_str(), read.mesh.triangles.size(), cpt.band.active_voxel_count(),
              cpt.band.brick_count(), cpt.band.voxel_size(), std::chrono::duration<double>(t2 - t1).count(),
              args.output.c_str(), human_bytes(written.file_bytes).c_str());
  if (cpt.open_edges > 0)
    std::fprintf(summary_stream(args.stats),
                 "%s: open mesh (%llu open edges): holes closed across %llu membrane voxels (%llu voxels beyond the mesh's band)%s\n",
                 args.mesh.c_str(), (unsigned long long)cpt.open_edges, (unsigned long long)cpt.membrane_voxels,
                 (unsigned long long)cpt.membrane_voxels_added,
                 cpt.membrane_truncated_bricks > 0 ? "; a membrane reaches past the mesh's box and stays open there" : "");

  Stats stats("cpt", cpt.band);
  stats.seconds["read"] = secs(t0, t1);
  stats.seconds["orient"] = cpt.seconds.orient;
  stats.seconds["bin"] = cpt.seconds.bin;
  stats.seconds["distance"] = cpt.seconds.distance;
  stats.seconds["sign"] = cpt.seconds.sign;
  stats.seconds["membrane"] = cpt.seconds.membrane;
  stats.seconds["assemble"] = cpt.seconds.assemble;
  stats.seconds["cpt"] = cpt.seconds.total;
  stats.seconds["write"] = secs(t2, t3);
  stats.seconds["total"] = secs(t0, t3);
  stats.extra["triangles"] = cpt.triangles;
  stats.extra["vertices"] = read.mesh.vertices.size();
  stats.extra["bricks"] = cpt.band.brick_count();
  stats.extra["voxel_size"] = cpt.band.voxel_size();
  stats.extra["brick_triangle_pairs"] = cpt.brick_triangle_pairs;
  stats.extra["method"] = cpt.method == CptMethod::slab_scan ? "slab" : "characteristic";
  stats.extra["polyhedra"] = cpt.polyhedra;
  stats.extra["distance_evaluations"] = cpt.evaluations;
  stats.extra["faces_flipped"] = cpt.faces_flipped;
  stats.extra["winding_queries"] = cpt.winding_queries;
  stats.extra["ray_queries"] = cpt.ray_queries;
  stats.extra["open_edges"] = cpt.open_edges;
  stats.extra["membrane_voxels"] = cpt.membrane_voxels;
  stats.extra["membrane_bricks_added"] = cpt.membrane_bricks_added;
  stats.extra["membrane_voxels_added"] = cpt.membrane_voxels_added;
  stats.extra["closest_points"] = args.closest_points;
  stats.extra["file_bytes"] = written.file_bytes;
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace levelset::cli
