// Before a subcommand does any work: its outputs may be written (core/file_io.hpp's
// check_output_paths). Outputs are the options -o/--output, --stats, --lsg, --mesh and --mask
// (stdout's "-" excepted); inputs are every other option value naming an existing file, so a
// new subcommand is covered by naming its options alike.
#pragma once

#include <CLI/CLI.hpp>

namespace levelset::cli {

void check_command_files(const CLI::App& sub);

}  // namespace levelset::cli
