#include "reconstruct_scoring.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "apps/mesh_distance.hpp"
#include "apps/sample_points.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "io/mesh_reader.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::bench {

double gross_threshold(const TriangleMesh& truth, double noise) {
  return std::max(kGrossFraction, kGrossNoise * noise) * length(truth.bounds().extent());
}

Row score(const TriangleMesh& truth, const std::vector<Vec3d>& truth_samples, const TriangleMesh& mesh, double seconds,
          double gross) {
  const MeshMeasures m = measure_mesh(mesh);
  Row row;
  row.seconds = seconds;
  row.genus = m.genus;
  row.watertight = m.watertight;
  row.components = m.components;
  if (mesh.triangles.empty()) return row;
  apps::SurfaceSampleOptions s;
  s.count = 200000;
  s.seed = 7;
  const std::vector<Vec3d> mesh_samples = apps::sample_mesh_surface(mesh, s);
  const apps::MeshDistance to_truth(truth), to_mesh(mesh);
  const apps::SurfaceDistance d = apps::surface_distance(
      mesh_samples, [&](const Vec3d& p) { return to_truth.distance(p); }, truth_samples,
      [&](const Vec3d& p) { return to_mesh.distance(p); }, {}, gross);
  row.chamfer = d.chamfer;
  row.hausdorff = d.hausdorff;
  row.gross = d.gross;
  return row;
}

namespace {

std::string script_path() { return std::string(LEVELSET_BENCH_DIR) + "/poisson_reference.py"; }

PoissonRun read_result(const std::string& ply, const std::string& reply) {
  PoissonRun run;
  const auto json = nlohmann::json::parse(reply, nullptr, false);
  if (json.is_discarded() || !json.contains("seconds")) {
    run.error = reply.empty() ? "no reply" : reply;
    return run;
  }
  try {
    run.mesh = read_mesh(ply).mesh;
  } catch (const Error& e) {
    run.error = e.what();
    return run;
  }
  run.seconds = json["seconds"].get<double>();
  run.ok = true;
  return run;
}

}  // namespace

PoissonRun run_poisson(const std::vector<Vec3d>& points, const std::string& cache) {
  namespace fs = std::filesystem;
  if (!cache.empty() && fs::exists(cache + ".json") && fs::exists(cache + ".ply")) {
    std::ifstream in(cache + ".json");
    const std::string reply((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    PoissonRun cached = read_result(cache + ".ply", reply);
    if (cached.ok) return cached;
  }
  const fs::path tmp = fs::temp_directory_path();
  const std::string stem = "bench_reconstruct_" + std::to_string(::getpid());
  const std::string xyz = (tmp / (stem + "_points.xyz")).string();
  const std::string ply = cache.empty() ? (tmp / (stem + "_poisson.ply")).string() : cache + ".ply";
  std::string text;
  char line[96];
  for (const Vec3d& p : points)
    text.append(line, std::size_t(std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", p.x, p.y, p.z)));
  write_file_atomically(xyz, text);
  const std::string cmd = "/usr/bin/python3 " + script_path() + " " + xyz + " " + ply + " 8 16";
  std::string reply;
  if (std::FILE* pipe = popen(cmd.c_str(), "r")) {
    std::array<char, 4096> buf{};
    while (std::fgets(buf.data(), int(buf.size()), pipe) != nullptr) reply += buf.data();
    pclose(pipe);
  }
  std::error_code ec;
  fs::remove(xyz, ec);
  PoissonRun run = read_result(ply, reply);
  if (run.ok && !cache.empty()) write_file_atomically(cache + ".json", reply);
  if (cache.empty()) fs::remove(ply, ec);
  return run;
}

}  // namespace levelset::bench
