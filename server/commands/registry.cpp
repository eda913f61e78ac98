// The list of self-registering subcommands (command.hpp). One line per subcommand.
#include "commands/number_checks.hpp"
#include "commands/command.hpp"

namespace levelset::cli {

void add_common_options(CLI::App* sub, int& threads, std::string& stats) {
  sub->add_option("--threads", threads, "Worker threads (default: all cores)")->transform(levelset::cli::in_range(1, 1024));
  sub->add_option("--stats", stats, "Write timings and sizes as JSON to FILE (or - for stdout)");
}

Command add_run_command(CLI::App& app, int& threads);
Command add_offset_command(CLI::App& app, int& threads);
Command add_fair_command(CLI::App& app, int& threads);
Command add_minmax_command(CLI::App& app, int& threads);
Command add_csg_command(CLI::App& app, int& threads);
Command add_path_command(CLI::App& app, int& threads);
Command add_voronoi_command(CLI::App& app, int& threads);
Command add_reconstruct_command(CLI::App& app, int& threads);
Command add_segment_command(CLI::App& app, int& threads);
Command add_serve_command(CLI::App& app, int& threads);

std::vector<Command> registered_commands(CLI::App& app, int& threads) {
  std::vector<Command> commands;
  commands.push_back(add_run_command(app, threads));
  commands.push_back(add_offset_command(app, threads));
  commands.push_back(add_fair_command(app, threads));
  commands.push_back(add_minmax_command(app, threads));
  commands.push_back(add_csg_command(app, threads));
  commands.push_back(add_path_command(app, threads));
  commands.push_back(add_voronoi_command(app, threads));
  commands.push_back(add_reconstruct_command(app, threads));
  commands.push_back(add_segment_command(app, threads));
  commands.push_back(add_serve_command(app, threads));
  return commands;
}

}  // namespace levelset::cli
