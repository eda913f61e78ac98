// levelsetd primitive SHAPE --resolution R --band W -o OUT.lsg: an analytic level set.
#include <chrono>
#include <cstdio>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

int run_primitive(const PrimitiveArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto shape = make_builtin_shape(args.shape);
  SdfBuildOptions options;
  options.frame = frame_for_resolution(shape->bounds(), args.resolution, args.band);
  const SdfBuildResult built = build_from_sdf(
      [&](const Vec3d& p) { return shape->distance(p); }, shape->bounds(), options);
  const auto t1 = std::chrono::steady_clock::now();
  const LsgWriteResult written = save_lsg(built.band, args.output);
  const auto t2 = std::chrono::steady_clock::now();

  const NarrowBand& band = built.band;
  std::fprintf(summary_stream(args.stats), "%s: %zu active voxels in %zu bricks, voxel size %.6g, %s in memory -> %s (%s)\n",
              args.shape.c_str(), band.active_voxel_count(), band.brick_count(), band.voxel_size(),
              human_bytes(band.memory_bytes()).c_str(), args.output.c_str(),
              human_bytes(written.file_bytes).c_str());

  Stats stats("primitive", band);
  stats.seconds["build"] = std::chrono::duration<double>(t1 - t0).count();
  stats.seconds["write"] = std::chrono::duration<double>(t2 - t1).count();
  stats.seconds["total"] = std::chrono::duration<double>(t2 - t0).count();
  stats.extra["shape"] = args.shape;
  stats.extra["resolution"] = args.resolution;
  stats.extra["voxel_size"] = band.voxel_size();
  stats.extra["bricks"] = band.brick_count();
  stats.extra["file_bytes"] = written.file_bytes;
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace levelset::cli
