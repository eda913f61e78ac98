// Before a subcommand does any work: its outputs may be written (core/file_io.hpp's
// check_output_paths). Outputs are the options -o/--output, --stats, --lsg, --mesh and --mask
// (stdout's "-" excepted); inputs are every other option value naming an existing file, so a
// new subcommand is covered by naming its options alike.
#pragma once

#include <CLI/CLI.hpp>

namespace levelset::cli {

void check_command_files(const CLI::App& sub);

// Validators for output options, run while the command line is parsed (before any work): the
// value's extension must name the format the option writes (core/file_extension.hpp).
CLI::Validator lsg_output();   // .lsg
CLI::Validator mesh_output();  // .off .obj .ply .stl .tria
CLI::Validator nrrd_output();  // .nrrd

}  // namespace levelset::cli
