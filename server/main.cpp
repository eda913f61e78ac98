// levelsetd: command line entry. Parses arguments (CLI11) and dispatches to subcommands;
// every levelset::Error becomes one line on stderr "levelsetd: <code> at <where>: <reason>"
// and exit code 1; usage errors exit with 2.
#include <cstdio>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "commands/number_checks.hpp"
#include "commands/command.hpp"
#include "commands/commands.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/malloc_policy.hpp"
#include "core/memory_budget.hpp"
#include "core/text.hpp"
#include "commands/output_check.hpp"
#include "evolve/speed.hpp"
#include "geometry/analytic_shapes.hpp"

using levelset::cli::add_common_options;

int main(int argc, char** argv) {
  levelset::keep_freed_memory();  // steps and requests reuse freed buffers (malloc_policy.hpp)
  CLI::App app{"levelsetd: narrow-band level-set computation (batch subcommands and the serve daemon)"};
  app.set_version_flag("--version", std::string("levelsetd ") + LEVELSET_VERSION);
  app.require_subcommand(1);
  bool allow_special = false;
  app.add_flag("--allow-special-outputs", allow_special,
               "Let outputs write into an existing character device or FIFO (e.g. --stats /dev/stdout); "
               "without it such destinations, and symbolic links, are refused");
  std::uint64_t memory_budget = 0;
  app.add_option("--memory-budget", memory_budget,
                 "Memory one command may allocate for what its input files claim, checked before reading "
                 "(e.g. 8G, 512MiB; default: half the physical memory, at most 4 GiB)")
      ->transform(CLI::AsSizeValue(false));
  int threads = 0;

  levelset::cli::InfoArgs info;
  CLI::App* info_cmd = app.add_subcommand("info", "Print what a mesh, point cloud, 3D image or .lsg file holds");
  info_cmd->add_option("file", info.path, "Input file (.lsg .off .tria .ply .obj .stl .xyz .xyzn .pwn .inr .inr.gz .nrrd .nhdr)")
      ->required();
  info_cmd->add_flag("--json", info.json, "Print JSON instead of text");

  levelset::cli::PrimitiveArgs prim;
  CLI::App* prim_cmd = app.add_subcommand("primitive", "Build the narrow band of an analytic shape");
  prim_cmd->add_option("shape", prim.shape, "sphere | box | torus | dumbbell | knot")
      ->required()
      ->check(CLI::IsMember(levelset::builtin_shape_names()));
  prim_cmd->add_option("--resolution,-r", prim.resolution,
                       "Voxels along the longest side of the padded bounding box")
      ->transform(levelset::cli::in_range(8, 1 << 15));
  prim_cmd->add_option("--band,-b", prim.band, "Band half-width in voxels")->transform(levelset::cli::in_range(1.0, 64.0));
  prim_cmd->add_option("-o,--output", prim.output, "Output .lsg file")->required()->check(levelset::cli::lsg_output());
  add_common_options(prim_cmd, threads, prim.stats);

  levelset::cli::CptArgs cpt;
  CLI::App* cpt_cmd = app.add_subcommand("cpt", "Closest point transform: triangle mesh -> signed narrow band");
  cpt_cmd->add_option("mesh", cpt.mesh, "Input mesh (.off .tria .ply .obj .stl)")->required();
  auto* res_opt = cpt_cmd->add_option("--resolution,-r", cpt.resolution,
                                      "Voxels along the longest side of the bounding box padded by the band")
                      ->transform(levelset::cli::in_range(8, 1 << 15));
  auto* vs_opt = cpt_cmd->add_option("--voxel-size", cpt.voxel_size, "Voxel size in mesh units")
                     ->transform(levelset::cli::positive());
  res_opt->excludes(vs_opt);
  cpt_cmd->add_option("--band,-b", cpt.band, "Band half-width in voxels")->transform(levelset::cli::in_range(1.0, 64.0));
  cpt_cmd->add_flag("--closest-points", cpt.closest_points, "Store the closest surface point per voxel");
  cpt_cmd->add_option("--method", cpt.method,
                      "characteristic (polyhedra per face, edge and vertex), slab (each triangle's slab) or auto "
                      "(the cheaper by an estimate); the same values either way")
      ->check(CLI::IsMember({"auto", "characteristic", "slab"}));
  cpt_cmd->add_option("-o,--output", cpt.output, "Output .lsg file")->required()->check(levelset::cli::lsg_output());
  add_common_options(cpt_cmd, threads, cpt.stats);

  levelset::cli::RedistanceArgs redist;
  CLI::App* redist_cmd = app.add_subcommand("redistance", "Restore the distance property (|grad u| = 1)");
  redist_cmd->add_option("input", redist.input, "Input .lsg")->required();
  redist_cmd->add_option("--method", redist.method, "sweep (fast sweeping) or march (fast marching)")
      ->check(CLI::IsMember({"sweep", "march"}));
  redist_cmd->add_option("--band,-b", redist.band, "New band half-width in voxels (default: keep)")
      ->transform(levelset::cli::in_range(1.0, 64.0));
  redist_cmd->add_option("--order", redist.order,
                         "Upwind order: 1 (first-order Godunov, the thesis's) or 2 (second order)")
      ->check(CLI::IsMember({1, 2}));
  redist_cmd->add_option("-o,--output", redist.output, "Output .lsg file")->required()->check(levelset::cli::lsg_output());
  add_common_options(redist_cmd, threads, redist.stats);

  levelset::cli::SampleArgs sample;
  CLI::App* sample_cmd = app.add_subcommand("sample", "Trilinearly interpolated values at points");
  sample_cmd->add_option("input", sample.input, "Input .lsg")->required();
  sample_cmd->add_option("--points", sample.points, "Points (.xyz .xyzn .pwn .ply)")->required();
  sample_cmd->add_option("-o,--output", sample.output, "Output text file, one value per line (default: stdout)");

  levelset::cli::MeshArgs mesh;
  CLI::App* mesh_cmd = app.add_subcommand("mesh", "Extract the iso-surface as a triangle mesh");
  mesh_cmd->add_option("input", mesh.input, "Input .lsg")->required();
  mesh_cmd->add_option("-o,--output", mesh.output, "Output mesh (.ply .obj .off .stl)")->required()->check(levelset::cli::mesh_output());
  mesh_cmd->add_option("--iso", mesh.iso, "Iso value (inside the band)");
  mesh_cmd->add_option("--method", mesh.method, "mc (marching cubes) or nets (surface nets)")
      ->check(CLI::IsMember({"mc", "nets"}));
  add_common_options(mesh_cmd, threads, mesh.stats);

  levelset::cli::MeasureArgs measure;
  CLI::App* measure_cmd = app.add_subcommand("measure", "Area, volume, components and genus of the surface");
  measure_cmd->add_option("input", measure.input, "Input .lsg")->required();
  measure_cmd->add_option("--iso", measure.iso, "Iso value (inside the band)");
  measure_cmd->add_option("--method", measure.method, "mc (marching cubes) or nets (surface nets)")
      ->check(CLI::IsMember({"mc", "nets"}));
  measure_cmd->add_flag("--json", measure.json, "Print JSON instead of text");

  levelset::cli::EvolveArgs evolve;
  CLI::App* evolve_cmd = app.add_subcommand("evolve", "Move the surface with a speed function (level set equation)");
  evolve_cmd->add_option("input", evolve.input, "Input .lsg")->required();
  evolve_cmd->add_option("-o,--output", evolve.output, "Output .lsg file")->required()->check(levelset::cli::lsg_output());
  std::string speed_help = "Speed: a formula (e.g. '1-eps*H', see the README) or a built-in name:";
  for (const std::string& n : levelset::evolve::builtin_speed_names()) speed_help += " " + n;
  evolve_cmd->add_option("--speed", evolve.speed, speed_help);
  evolve_cmd->add_option("--const", evolve.constants, "Named constant for the formula, NAME=VALUE (repeatable)");
  evolve_cmd->add_option("--c", evolve.c, "Speed constant (constant, one-minus-eps-kappa)");
  evolve_cmd->add_option("--eps", evolve.eps, "Curvature weight (one-minus-eps-kappa)");
  evolve_cmd->add_option("--velocity", evolve.velocity, "Constant advection velocity x,y,z (world units per time)")
      ->delimiter(',')
      ->expected(3);
  auto* steps_opt = evolve_cmd->add_option("--steps", evolve.steps, "Number of time steps")->transform(levelset::cli::positive_int());
  auto* time_opt = evolve_cmd->add_option("--time", evolve.time, "Evolve until this time")->transform(levelset::cli::positive());
  steps_opt->excludes(time_opt);
  evolve_cmd->add_option("--scheme", evolve.scheme, "Spatial scheme: godunov (first order), eno2, weno5")
      ->check(CLI::IsMember({"godunov", "eno2", "weno5"}));
  evolve_cmd->add_option("--hamiltonian", evolve.hamiltonian, "godunov, or llf (Local Lax-Friedrichs)")
      ->check(CLI::IsMember({"godunov", "llf"}));
  evolve_cmd->add_option("--rk", evolve.rk, "Time integration: 1 (forward Euler) or 3 (TVD-RK3)")
      ->check(CLI::IsMember({1, 3}));
  evolve_cmd->add_option("--cfl", evolve.cfl, "CFL number in (0, 1] (default 0.5 for --rk 1, 0.9 for --rk 3)")->transform(levelset::cli::in_range(1e-6, 1.0));
  evolve_cmd->add_option("--redistance-every", evolve.redistance_every, "Redistance every K steps (0: never)")
      ->transform(levelset::cli::non_negative_int());
  evolve_cmd->add_option("--drift-tolerance", evolve.drift_tolerance,
                         "Redistance when the mean ||grad u| - 1| near the surface exceeds this (0: off)")
      ->transform(levelset::cli::non_negative())
      ->capture_default_str();
  evolve_cmd->add_option("--band-growth-limit", evolve.band_growth_limit,
                         "Redistance when the band holds more than this many times a fresh band's voxels (0: off, else >= 1)")
      ->transform(levelset::cli::in_range(0.0, 1e6))
      ->capture_default_str();
  evolve_cmd->add_flag("--extension", evolve.extension, "Extension velocities (speed constant along normals)");
  evolve_cmd->add_option("--report-every", evolve.report_every, "Print a progress line every N steps")
      ->transform(levelset::cli::non_negative_int());
  add_common_options(evolve_cmd, threads, evolve.stats);

  const std::vector<levelset::cli::Command> registered = levelset::cli::registered_commands(app, threads);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "levelsetd: usage: %s (see levelsetd --help)\n", levelset::sanitize_utf8(e.what()).c_str());
    return 2;
  }

  if (memory_budget > 0) levelset::set_default_memory_budget(memory_budget);
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);

  // Outputs never clobber: no symlink or special file replaced, no input overwritten (checked
  // here before any work, and again at each write), no temp file left by Ctrl-C.
  levelset::remove_temp_files_on_signals();
  levelset::enable_output_guard(true);
  levelset::allow_special_outputs(allow_special);
  try {
    for (const CLI::App* sub : app.get_subcommands()) levelset::cli::check_command_files(*sub);
    if (*info_cmd) return levelset::cli::run_info(info);
    if (*prim_cmd) return levelset::cli::run_primitive(prim);
    if (*cpt_cmd) return levelset::cli::run_cpt(cpt);
    if (*redist_cmd) return levelset::cli::run_redistance(redist);
    if (*sample_cmd) return levelset::cli::run_sample(sample);
    if (*mesh_cmd) return levelset::cli::run_mesh(mesh);
    if (*measure_cmd) return levelset::cli::run_measure(measure);
    if (*evolve_cmd) {
      if (evolve.steps == 0 && evolve.time == 0.0) {
        std::fprintf(stderr, "levelsetd: usage: evolve needs --steps N or --time T (see levelsetd evolve --help)\n");
        return 2;
      }
      if (evolve.speed.empty() && evolve.velocity.empty()) {
        std::fprintf(stderr, "levelsetd: usage: evolve needs --speed NAME or --velocity x,y,z (see levelsetd evolve --help)\n");
        return 2;
      }
      return levelset::cli::run_evolve(evolve);
    }
    for (const levelset::cli::Command& command : registered)
      if (*command.sub) return command.run();
  } catch (const levelset::Error& e) {
    std::fprintf(stderr, "levelsetd: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "levelsetd: out of memory\n");
    return 1;
  } catch (const std::exception& e) {  // not ours (a library's): still one line and exit 1
    std::fprintf(stderr, "levelsetd: internal error: %s\n", levelset::sanitize_utf8(e.what()).c_str());
    return 1;
  }
  return 2;
}
