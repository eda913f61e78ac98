// levelsetd: command line entry. Parses arguments (CLI11) and dispatches to subcommands;
// every levelset::Error becomes one line on stderr "levelsetd: <code> at <where>: <reason>"
// and exit code 1; usage errors exit with 2.
#include <cstdio>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "commands/commands.hpp"
#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"

namespace {

void add_threads_option(CLI::App* sub, int& threads) {
  sub->add_option("--threads", threads, "Worker threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"levelsetd: narrow-band level-set computation (batch subcommands; daemon to come)"};
  app.set_version_flag("--version", std::string("levelsetd ") + LEVELSET_VERSION);
  app.require_subcommand(1);

  levelset::cli::InfoArgs info;
  CLI::App* info_cmd = app.add_subcommand("info", "Print what a mesh, point cloud or .lsg file holds");
  info_cmd->add_option("file", info.path, "Input file (.lsg .off .tria .ply .obj .stl .xyz .xyzn .pwn)")
      ->required();
  info_cmd->add_flag("--json", info.json, "Print JSON instead of text");

  levelset::cli::PrimitiveArgs prim;
  CLI::App* prim_cmd = app.add_subcommand("primitive", "Build the narrow band of an analytic shape");
  prim_cmd->add_option("shape", prim.shape, "sphere | box | torus | dumbbell | knot")
      ->required()
      ->check(CLI::IsMember(levelset::builtin_shape_names()));
  prim_cmd->add_option("--resolution,-r", prim.resolution,
                       "Voxels along the longest side of the padded bounding box")
      ->check(CLI::Range(8, 1 << 15));
  prim_cmd->add_option("--band,-b", prim.band, "Band half-width in voxels")->check(CLI::Range(1.0, 64.0));
  prim_cmd->add_option("-o,--output", prim.output, "Output .lsg file")->required();
  prim_cmd->add_option("--stats", prim.stats, "Write timing statistics as JSON to FILE (or - for stdout)");
  add_threads_option(prim_cmd, prim.threads);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "levelsetd: usage: %s (see levelsetd --help)\n", e.what());
    return 2;
  }

  std::optional<tbb::global_control> limit;
  const int threads = prim.threads;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);

  try {
    if (*info_cmd) return levelset::cli::run_info(info);
    if (*prim_cmd) return levelset::cli::run_primitive(prim);
  } catch (const levelset::Error& e) {
    std::fprintf(stderr, "levelsetd: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "levelsetd: out of memory\n");
    return 1;
  }
  return 2;
}
