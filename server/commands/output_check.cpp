#include "commands/output_check.hpp"

#include <filesystem>
#include <string>
#include <vector>

#include "core/file_io.hpp"

namespace levelset::cli {

namespace {
bool is_output_option(const CLI::Option& o) {
  for (const std::string& name : o.get_lnames())
    if (name == "output" || name == "stats" || name == "lsg" || name == "mesh" || name == "mask") return true;
  return false;
}
}  // namespace

void check_command_files(const CLI::App& sub) {
  std::vector<std::filesystem::path> inputs, outputs;
  for (const CLI::Option* o : sub.get_options()) {
    if (o->count() == 0) continue;
    const bool output = is_output_option(*o);
    for (const std::string& value : o->results()) {
      if (value.empty() || value == "-") continue;
      std::error_code ec;
      if (output)
        outputs.emplace_back(value);
      else if (std::filesystem::is_regular_file(value, ec))
        inputs.emplace_back(value);
    }
  }
  check_output_paths(inputs, outputs);
}

}  // namespace levelset::cli
