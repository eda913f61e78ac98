#include "commands/output_check.hpp"

#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/file_extension.hpp"
#include "core/file_io.hpp"
#include "commands/report.hpp"

namespace levelset::cli {

namespace {
CLI::Validator extension_validator(std::span<const std::string_view> allowed, std::string what) {
  return CLI::Validator(
      [allowed, what](std::string& value) -> std::string {
        try {
          require_extension(value, allowed, what);
          return {};
        } catch (const Error& e) {
          return e.reason();
        }
      },
      "FILE", "");
}

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
  // An output that is the process's stdout (/dev/stdout, /proc/self/fd/1): the summary line
  // moves to stderr so that it does not mix with the data.
  struct stat out_st{}, stdout_st{};
  bool on_stdout = false;
  if (::fstat(1, &stdout_st) == 0)
    for (const std::filesystem::path& p : outputs)
      if (::stat(p.c_str(), &out_st) == 0 && out_st.st_dev == stdout_st.st_dev && out_st.st_ino == stdout_st.st_ino)
        on_stdout = true;
  set_output_on_stdout(on_stdout);
}

CLI::Validator lsg_output() { return extension_validator(kLsgExtensions, "a narrow band"); }
CLI::Validator mesh_output() { return extension_validator(kMeshOutputExtensions, "a mesh"); }
CLI::Validator nrrd_output() { return extension_validator(kNrrdOutputExtensions, "an NRRD image"); }

}  // namespace levelset::cli
