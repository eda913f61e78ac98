// levelsetd measure IN.lsg [--iso V] [--method mc|nets] [--json]: area, volume, topology.
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "grid/lsg_file.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::cli {

int run_measure(const MeasureArgs& args) {
  const LsgReadResult in = load_lsg(args.input);
  const SurfaceResult surface = extract_surface(in.band, args.method, args.iso);
  const MeshMeasures m = measure_mesh(surface.mesh);
  nlohmann::json j;
  j["file"] = args.input;
  j["iso"] = args.iso;
  j["method"] = args.method;
  j["area"] = m.area;
  j["volume"] = m.volume;
  j["euler_characteristic"] = m.euler_characteristic;
  j["genus"] = m.genus;
  j["components"] = m.components;
  j["vertices"] = m.vertices;
  j["triangles"] = m.faces;
  j["watertight"] = m.watertight;
  j["manifold"] = m.manifold;
  j["boundary_edges"] = m.boundary_edges;
  j["non_manifold_edges"] = m.non_manifold_edges;
  if (!m.bounds.empty())
    j["bounds"] = {{"min", {m.bounds.min.x, m.bounds.min.y, m.bounds.min.z}},
                   {"max", {m.bounds.max.x, m.bounds.max.y, m.bounds.max.z}}};
  if (args.json) {
    std::cout << json_text(j) << "\n";
    return 0;
  }
  std::printf("file:            %s (iso %g, %s)\n", args.input.c_str(), args.iso, args.method.c_str());
  std::printf("area:            %.9g\n", m.area);
  std::printf("volume:          %.9g\n", m.volume);
  std::printf("components:      %llu\n", (unsigned long long)m.components);
  std::printf("euler / genus:   %lld / %g\n", (long long)m.euler_characteristic, m.genus);
  std::printf("mesh:            %llu vertices, %llu triangles, %s\n", (unsigned long long)m.vertices,
              (unsigned long long)m.faces, m.watertight && m.manifold ? "watertight and manifold" : "open or non-manifold");
  if (!m.bounds.empty())
    std::printf("bounds:          (%.10g, %.10g, %.10g) - (%.10g, %.10g, %.10g)\n", m.bounds.min.x, m.bounds.min.y,
                m.bounds.min.z, m.bounds.max.x, m.bounds.max.y, m.bounds.max.z);
  return 0;
}

}  // namespace levelset::cli
