// levelsetd mesh IN.lsg -o OUT.(ply|obj|off|stl) [--iso V] [--method mc|nets]: extract the surface.
#include <chrono>
#include <cstdio>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "grid/lsg_file.hpp"
#include "io/mesh_writer.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/iso_range.hpp"
#include "surface/mesh_measures.hpp"
#include "surface/surface_nets.hpp"

namespace levelset::cli {

SurfaceResult extract_surface(const NarrowBand& band, const std::string& method, double iso) {
  check_iso_in_band(band, iso, "--iso");
  if (method == "nets") {
    SurfaceNetsOptions options;
    options.iso = iso;
    return surface_nets(band, options);
  }
  MarchingCubesOptions options;
  options.iso = iso;
  return marching_cubes(band, options);
}

int run_mesh(const MeshArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const LsgReadResult in = load_lsg(args.input);
  const auto t1 = std::chrono::steady_clock::now();
  const SurfaceResult surface = extract_surface(in.band, args.method, args.iso);
  const auto t2 = std::chrono::steady_clock::now();
  write_mesh(surface.mesh, args.output);
  const auto t3 = std::chrono::steady_clock::now();
  const MeshMeasures m = measure_mesh(surface.mesh);

  std::fprintf(summary_stream(args.stats), "%s: %zu vertices, %zu triangles (%s, iso %g), %s, %.3f s -> %s\n",
               args.input.c_str(), surface.mesh.vertices.size(), surface.mesh.triangles.size(),
               args.method.c_str(), args.iso,
               m.watertight && m.manifold ? "watertight and manifold" : "open or non-manifold",
               secs(t1, t2), args.output.c_str());
  Stats stats("mesh", in.band);
  stats.set_phases("extract", t0, t1, t2, t3);
  stats.extra["method"] = args.method;
  stats.extra["iso"] = args.iso;
  stats.extra["vertices"] = surface.mesh.vertices.size();
  stats.extra["triangles"] = surface.mesh.triangles.size();
  stats.extra["watertight"] = m.watertight;
  stats.extra["manifold"] = m.manifold;
  stats.extra["min_angle_deg"] = m.min_angle_deg;
  stats.extra["mean_min_angle_deg"] = m.mean_min_angle_deg;
  stats.extra["max_aspect_ratio"] = m.max_aspect_ratio;
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace levelset::cli
