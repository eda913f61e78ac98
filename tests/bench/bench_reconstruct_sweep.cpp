// bench_reconstruct --sweep (issue 19): levelset's reconstruction with default options against
// Open3D's screened Poisson on every closed, manifold mesh of CGAL's data/meshes with at least
// 2,000 faces; points sampled by area (seeded), Gaussian noise as a fraction of the bounding-box
// diagonal; the same points for both. Per case: Chamfer and Hausdorff (printed over the
// diagonal; world units in the --jsonl records, with the diagonal and our coverage),
// watertight, genus, components (against the true mesh's), seconds, and the share of each
// Chamfer carried by gross errors (distances above max(0.5 %, 3 noise) of the diagonal: missed or
// fused parts, closed gaps). Then a summary: wins and losses on Chamfer, the median ratio, the
// losses that the gross errors decide (ours ahead once each side's gross part is taken out),
// topology failures both ways, time.
// Meshes whose features are thinner than 2 voxels at the resolution are measured and marked
// ("thin": the share of the surface where a part facing the other way lies within 2 voxels,
// inside or outside; see thin_share), and summarised apart as well, never dropped.
//
// Options: --points 20000,50000,200000  --noise 0,0.001,0.005  --seeds 1 2  --resolution 256
//   --meshes a.off,b.off (only these)  --max-meshes N  --ours (no Poisson)  --list (the meshes
//   and their measurements only)  --jsonl FILE (one record per case, appended)
//   --cache DIR (Poisson's results by case, default reconstruct-sweep-cache; reused).
//   Development: --levels L, --shell-offset S, --curvature-weight W, --free-distance F, --no-carve,
//   --no-web-tunnels, --no-cut-sheets, --no-refit-moved, --no-widen-smooth, --no-facing-points
//   (reconstruction options);
//   --keep DIR writes each case's points (KEY-points.xyz) and our surface (KEY-ours.ply);
//   --log: the reconstruction's per-level lines with each level's topology on stderr.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/mesh_distance.hpp"
#include "apps/point_distance.hpp"
#include "apps/reconstruction.hpp"
#include "apps/sample_points.hpp"
#include "core/error.hpp"
#include "geometry/point_triangle.hpp"
#include "io/mesh_reader.hpp"
#include "io/mesh_writer.hpp"
#include "reconstruct_scoring.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::bench {

namespace {

namespace fs = std::filesystem;

struct SweepOptions {
  std::vector<std::size_t> points{20000, 50000, 200000};
  std::vector<double> noise{0.0, 0.001, 0.005};
  unsigned seed_first = 1, seed_last = 2;
  int resolution = 256;
  std::vector<std::string> meshes;
  std::size_t max_meshes = 0;
  bool ours_only = false, list_only = false;
  std::string jsonl, cache = "reconstruct-sweep-cache";
  // Development switches (not the defaults' measurement): reconstruction options.
  int levels = 0;
  double shell_offset = 0, curvature_weight = -1, free_distance = -1;
  std::string keep;
  bool log = false;  // the reconstruction's per-level lines and topology on stderr
  bool no_carve = false;
  bool no_web_tunnels = false;
  bool no_cut_sheets = false;
  bool no_refit_moved = false;
  bool no_widen_smooth = false;
  bool no_facing_points = false;
};

template <class T>
std::vector<T> parse_list(const std::string& text) {
  std::vector<T> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) continue;
    if constexpr (std::is_same_v<T, std::string>) out.push_back(item);
    else out.push_back(T(std::strtod(item.c_str(), nullptr)));
  }
  return out;
}

SweepOptions parse(int argc, char** argv) {
  SweepOptions o;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool value = a + 1 < argc;
    if (value && arg == "--points") o.points = parse_list<std::size_t>(argv[++a]);
    else if (value && arg == "--noise") o.noise = parse_list<double>(argv[++a]);
    else if (a + 2 < argc && arg == "--seeds") {
      o.seed_first = unsigned(std::strtoul(argv[++a], nullptr, 10));
      o.seed_last = std::max(o.seed_first, unsigned(std::strtoul(argv[++a], nullptr, 10)));
    } else if (value && arg == "--resolution") o.resolution = std::atoi(argv[++a]);
    else if (value && arg == "--meshes") o.meshes = parse_list<std::string>(argv[++a]);
    else if (value && arg == "--max-meshes") o.max_meshes = std::size_t(std::atol(argv[++a]));
    else if (value && arg == "--jsonl") o.jsonl = argv[++a];
    else if (value && arg == "--cache") o.cache = argv[++a];
    else if (value && arg == "--levels") o.levels = std::atoi(argv[++a]);
    else if (value && arg == "--shell-offset") o.shell_offset = std::atof(argv[++a]);
    else if (value && arg == "--curvature-weight") o.curvature_weight = std::atof(argv[++a]);
    else if (value && arg == "--keep") o.keep = argv[++a];
    else if (value && arg == "--free-distance") o.free_distance = std::atof(argv[++a]);
    else if (arg == "--ours") o.ours_only = true;
    else if (arg == "--list") o.list_only = true;
    else if (arg == "--log") o.log = true;
    else if (arg == "--no-carve") o.no_carve = true;
    else if (arg == "--no-web-tunnels") o.no_web_tunnels = true;
    else if (arg == "--no-cut-sheets")
      o.no_cut_sheets = true;
    else if (arg == "--no-refit-moved") o.no_refit_moved = true;
    else if (arg == "--no-widen-smooth") o.no_widen_smooth = true;
    else if (arg == "--no-facing-points") o.no_facing_points = true;
  }
  return o;
}

// The resolution the thin-feature measure refers to: the given one, or 256 (the issue's
// protocol) when ours chooses its own from the data (--resolution 0).
int thin_resolution(const SweepOptions& o) { return o.resolution > 0 ? o.resolution : 256; }

struct SweepMesh {
  std::string name;
  TriangleMesh mesh;
  MeshMeasures measures;
  double diagonal = 0;
  double thin = 0;  // share of the area with features thinner than ~2 voxels
};

// The share of the surface (area samples) where another part of the surface facing the other
// way lies within 2 voxels: a part thinner than 2 h (a probe h inside, a triangle within
// 0.9 h of it whose normal opposes the sample's), or a gap narrower than 2 h (the same outside).
// Faces meeting at a crease are not opposite (their normals differ by <= ~120 degrees), so
// sharp edges do not count.
double thin_share(const TriangleMesh& mesh, double h) {
  std::vector<double> cdf;
  std::vector<Vec3d> normals, centres;
  double total = 0, reach = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3d a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const Vec3d n = cross(b - a, c - a);
    const double area = 0.5 * length(n);
    total += area;
    cdf.push_back(total);
    normals.push_back(area > 0 ? n / (2 * area) : Vec3d{0, 0, 0});
    const Vec3d centre = (a + b + c) / 3.0;
    centres.push_back(centre);
    for (const Vec3d& v : {a, b, c}) reach = std::max(reach, length(v - centre));
  }
  if (total <= 0) return 0;
  const apps::PointIndex index(centres);
  auto opposite_near = [&](const Vec3d& q, const Vec3d& n, std::vector<std::pair<std::uint32_t, double>>& near) {
    index.within(q, 0.9 * h + reach, near);
    for (const auto& [f, d2] : near) {
      if (dot(normals[f], n) > -0.5) continue;
      const auto& t = mesh.triangles[f];
      if (closest_point_on_triangle(q, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]).distance_squared <
          0.81 * h * h)
        return true;
    }
    return false;
  };
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  const int samples = 20000;
  int thin = 0;
  std::vector<std::pair<std::uint32_t, double>> near;
  for (int i = 0; i < samples; ++i) {
    const std::size_t f =
        std::min(std::size_t(std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin()), cdf.size() - 1);
    const auto& t = mesh.triangles[f];
    const double r1 = std::sqrt(u(rng)), r2 = u(rng);
    const Vec3d p = mesh.vertices[t[0]] * (1 - r1) + mesh.vertices[t[1]] * (r1 * (1 - r2)) + mesh.vertices[t[2]] * (r1 * r2);
    thin += opposite_near(p - normals[f] * h, normals[f], near) || opposite_near(p + normals[f] * h, normals[f], near);
  }
  return double(thin) / samples;
}

// The meshes of the sweep, and one line for each file left out (with the reason).
std::vector<SweepMesh> sweep_meshes(const SweepOptions& o) {
  const fs::path dir = fs::path(LEVELSET_CGAL_DATA) / "meshes";
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<SweepMesh> out;
  for (const fs::path& f : files) {
    const std::string name = f.filename().string();
    if (!o.meshes.empty() && std::find(o.meshes.begin(), o.meshes.end(), name) == o.meshes.end()) continue;
    SweepMesh m;
    m.name = name;
    try {
      m.mesh = read_mesh(f).mesh;
    } catch (const Error& e) {
      std::printf("  left out %-28s not read: %s\n", name.c_str(), e.what());
      continue;
    }
    m.measures = measure_mesh(m.mesh);
    if (!m.measures.watertight || m.mesh.triangles.size() < 2000) {
      std::printf("  left out %-28s %zu faces, %s\n", name.c_str(), m.mesh.triangles.size(),
                  m.measures.watertight ? "fewer than 2000 faces" : "not closed and manifold");
      continue;
    }
    m.diagonal = length(m.mesh.bounds().extent());
    const Vec3d e = m.mesh.bounds().extent();
    const double longest = std::max({e.x, e.y, e.z});
    m.thin = thin_share(m.mesh, longest / (thin_resolution(o) - 10));
    out.push_back(std::move(m));
    if (o.max_meshes > 0 && out.size() >= o.max_meshes) break;
  }
  return out;
}

struct CaseResult {
  std::string mesh;
  std::size_t points = 0;
  double noise = 0;
  unsigned seed = 0;
  bool thin = false;
  double truth_genus = 0, diagonal = 1;
  std::uint64_t truth_components = 0;
  Row ours, poisson;
  bool has_poisson = false;
  double ours_resolution = 0;
  double ours_coverage = 0;  // share of the points near our surface (ReconstructionResult::coverage)
};

bool topology_right(const Row& r, const CaseResult& c) {
  return r.watertight && std::abs(r.genus - c.truth_genus) < 0.25 && r.components == c.truth_components;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void summarise(const std::vector<CaseResult>& cases, const char* title) {
  std::size_t n = 0, wins = 0, leaky = 0, ours_wrong = 0, poisson_wrong = 0, both_wrong = 0, gross_losses = 0;
  std::vector<double> ratios, time_ratios;
  for (const CaseResult& c : cases) {
    leaky += !c.ours.watertight;
    if (!c.has_poisson) continue;
    ++n;
    const double ratio = c.ours.chamfer / std::max(1e-300, c.poisson.chamfer);
    ratios.push_back(ratio);
    time_ratios.push_back(c.ours.seconds / std::max(1e-9, c.poisson.seconds));
    wins += ratio <= 1.0;
    // A loss that the gross errors decide: without each side's gross part, ours is ahead.
    gross_losses += ratio > 1.0 && c.ours.chamfer - c.ours.gross <= c.poisson.chamfer - c.poisson.gross;
    const bool o = topology_right(c.ours, c), p = topology_right(c.poisson, c);
    ours_wrong += !o && p;
    poisson_wrong += o && !p;
    both_wrong += !o && !p;
  }
  std::printf("summary %-22s cases %zu | chamfer: ours <= poisson in %zu (%.1f %%), median ratio %.3f, losses "
              "decided by gross errors %zu of %zu | not watertight (ours) %zu | topology: ours wrong where poisson "
              "right %zu, poisson wrong where ours right %zu, both wrong %zu | median time ratio %.2f\n",
              title, n, wins, n ? 100.0 * double(wins) / double(n) : 0.0, median(ratios), gross_losses, n - wins,
              leaky, ours_wrong, poisson_wrong, both_wrong, median(time_ratios));
}

nlohmann::json row_json(const Row& r) {
  return {{"chamfer", r.chamfer},     {"hausdorff", r.hausdorff}, {"gross", r.gross}, {"seconds", r.seconds},
          {"watertight", r.watertight}, {"genus", r.genus},       {"components", r.components}};
}

CaseResult run_case(const SweepMesh& m, const std::vector<Vec3d>& truth_samples, std::size_t count, double noise,
                    unsigned seed, const SweepOptions& o) {
  CaseResult c;
  c.mesh = m.name, c.points = count, c.noise = noise, c.seed = seed, c.thin = m.thin > 0.005;
  c.truth_genus = m.measures.genus, c.truth_components = m.measures.components, c.diagonal = m.diagonal;
  apps::SurfaceSampleOptions ps;
  ps.count = count;
  ps.noise = noise * m.diagonal;
  ps.seed = seed;
  const std::vector<Vec3d> points = apps::sample_mesh_surface(m.mesh, ps);
  apps::ReconstructionOptions ro;  // the defaults, as `levelsetd reconstruct --resolution R`
  ro.resolution = o.resolution;
  if (o.levels > 0) ro.levels = o.levels;
  if (o.shell_offset > 0) ro.shell_offset = o.shell_offset;
  if (o.curvature_weight >= 0) ro.curvature_weight = o.curvature_weight;
  if (o.free_distance >= 0) ro.free_distance = o.free_distance;
  ro.carve_gaps = !o.no_carve;
  ro.web_tunnels = !o.no_web_tunnels;
  ro.cut_sheets = !o.no_cut_sheets;
  ro.refit_moved = !o.no_refit_moved;
  ro.widen_smooth = !o.no_widen_smooth;
  ro.facing_points = !o.no_facing_points;
  if (o.log) {
    ro.log = [](const std::string& line) { std::fprintf(stderr, "  %s\n", line.c_str()); };
    ro.log_topology = true;
  }
  const auto t0 = std::chrono::steady_clock::now();
  try {
    const apps::ReconstructionResult r = apps::reconstruct_surface(points, ro);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    c.ours = score(m.mesh, truth_samples, r.mesh, seconds, gross_threshold(m.mesh, noise));
    c.ours_resolution = r.resolution;
    c.ours_coverage = r.coverage;
    if (!o.keep.empty()) {
      char key[256];
      std::snprintf(key, sizeof key, "%s-%zu-%g-%u", m.name.c_str(), count, noise, seed);
      fs::create_directories(o.keep);
      write_mesh(r.mesh, fs::path(o.keep) / (std::string(key) + "-ours.ply"));
      std::ofstream xyz(fs::path(o.keep) / (std::string(key) + "-points.xyz"));
      for (const Vec3d& p : points) xyz << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
  } catch (const Error& e) {
    std::printf("  %s: ours failed: %s\n", m.name.c_str(), e.what());
  }
  if (!o.ours_only) {
    std::error_code ec;
    fs::create_directories(o.cache, ec);
    char key[256];
    std::snprintf(key, sizeof key, "%s-%zu-%g-%u", m.name.c_str(), count, noise, seed);
    const PoissonRun p = run_poisson(points, (fs::path(o.cache) / key).string());
    if (p.ok) {
      c.poisson = score(m.mesh, truth_samples, p.mesh, p.seconds, gross_threshold(m.mesh, noise));
      c.has_poisson = true;
    } else {
      std::printf("  %s: poisson failed: %s\n", m.name.c_str(), p.error.c_str());
    }
  }
  return c;
}

void print_case(const CaseResult& c, const SweepOptions& o) {
  const double ratio = c.has_poisson ? c.ours.chamfer / std::max(1e-300, c.poisson.chamfer) : 0;
  auto topo = [&](const Row& r) {
    char s[48];
    std::snprintf(s, sizeof s, "%s g%g c%llu", r.watertight ? "wt" : "LEAK", r.genus,
                  static_cast<unsigned long long>(r.components));
    return std::string(s);
  };
  auto share = [](const Row& r) { return r.chamfer > 0 ? r.gross / r.chamfer : 0.0; };
  std::printf("%-24s %7zu %5.2f%% %2u%s | %9.3e %9.3e %6.3f | %4.2f %4.2f | %9.3e %9.3e | %-14s %-14s g%g c%llu | %6.2f %6.2f\n",
              c.mesh.c_str(), c.points, c.noise * 100, c.seed, c.thin ? "T" : " ", c.ours.chamfer / c.diagonal,
              c.poisson.chamfer / c.diagonal, ratio, share(c.ours), share(c.poisson), c.ours.hausdorff / c.diagonal,
              c.poisson.hausdorff / c.diagonal,
              topo(c.ours).c_str(),
              c.has_poisson ? topo(c.poisson).c_str() : "-", c.truth_genus,
              static_cast<unsigned long long>(c.truth_components), c.ours.seconds, c.poisson.seconds);
  std::fflush(stdout);
  if (o.jsonl.empty()) return;
  nlohmann::json j = {{"mesh", c.mesh},   {"points", c.points}, {"noise", c.noise},
                      {"seed", c.seed},   {"thin", c.thin},     {"truth", {{"genus", c.truth_genus}, {"components", c.truth_components}}},
                      {"ours", row_json(c.ours)}, {"resolution", c.ours_resolution}, {"coverage", c.ours_coverage},
                      {"diagonal", c.diagonal}};
  if (c.has_poisson) j["poisson"] = row_json(c.poisson);
  std::ofstream(o.jsonl, std::ios::app) << j.dump() << "\n";
}

}  // namespace

int run_reconstruct_sweep(int argc, char** argv) {
  const SweepOptions o = parse(argc, argv);
  std::printf("bench_reconstruct --sweep: CGAL's closed manifold meshes (>= 2000 faces), resolution %d, defaults; "
              "Chamfer and Hausdorff over the bbox diagonal; reference Open3D screened Poisson depth 8\n",
              o.resolution);
  const std::vector<SweepMesh> meshes = sweep_meshes(o);
  for (const SweepMesh& m : meshes)
    std::printf("  mesh %-28s %7zu faces genus %g components %llu thin %.2f %%%s\n", m.name.c_str(),
                m.mesh.triangles.size(), m.measures.genus, static_cast<unsigned long long>(m.measures.components),
                100 * m.thin, m.thin > 0.005 ? " (features thinner than 2 voxels: marked T)" : "");
  if (o.list_only) return 0;
  // gross: the share of each Chamfer carried by distances above gross_threshold (reconstruct_scoring.hpp).
  std::printf("%-24s %7s %6s %3s | %9s %9s %6s | %9s | %9s %9s | %-14s %-14s %-6s | %6s %6s\n", "mesh", "points", "noise",
              "sd", "ours_ch/D", "pois_ch/D", "ratio", "gross o p", "ours_hd/D", "pois_hd/D", "ours topo", "poisson topo",
              "truth", "ours_s", "pois_s");
  std::vector<CaseResult> all;
  for (const SweepMesh& m : meshes) {
    apps::SurfaceSampleOptions ts;
    ts.count = 200000;
    ts.seed = 11;
    const std::vector<Vec3d> truth_samples = apps::sample_mesh_surface(m.mesh, ts);
    for (std::size_t count : o.points)
      for (double noise : o.noise)
        for (unsigned seed = o.seed_first; seed <= o.seed_last; ++seed) {
          all.push_back(run_case(m, truth_samples, count, noise, seed, o));
          print_case(all.back(), o);
        }
  }
  summarise(all, "all");
  std::vector<CaseResult> resolved;
  for (const CaseResult& c : all)
    if (!c.thin) resolved.push_back(c);
  summarise(resolved, "without thin meshes");
  bool watertight = true;
  for (const CaseResult& c : all) watertight = watertight && c.ours.watertight;
  return watertight ? 0 : 1;
}

}  // namespace levelset::bench
