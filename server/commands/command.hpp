// A batch subcommand that registers itself: its file adds the CLI11 subcommand with its
// options (bound to state the returned `run` captures) and returns how to run it. main.cpp
// keeps the list (registered_commands) and runs the one the user chose.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace levelset::cli {

struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;  // exit code; levelset::Error propagates to main
};

// --threads and --stats, the options every long-running subcommand takes.
void add_common_options(CLI::App* sub, int& threads, std::string& stats);

// The self-registering subcommands (one file each under server/commands/).
std::vector<Command> registered_commands(CLI::App& app, int& threads);

}  // namespace levelset::cli
