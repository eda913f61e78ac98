// JobContext::check_outputs: a job's outputs checked before it computes anything (issue 14: a
// job with `input { mesh = bunny.off }` and `output { mesh = off }` run with `-o .` beside it
// replaced bunny.off; `--set output.mesh=plyx` failed only after the computation).
#include <cctype>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "jobs/job_context.hpp"

namespace levelset::jobs {

namespace fs = std::filesystem;

namespace {

// Extensions of the files a job writes: bands, meshes, images, paths, its log and stats.
constexpr std::string_view kJobOutputExtensions[] = {".lsg", ".ply", ".obj", ".off", ".stl", ".tria",
                                                     ".nrrd", ".txt", ".log", ".json"};

bool is_output_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (std::string_view e : kJobOutputExtensions)
    if (e == ext) return true;
  return false;
}

// Calls f(entry, path) for every word or string value of the tree that names an existing
// regular file (relative names against base_dir; cgal: names are read-only sample data).
template <typename F>
void for_each_named_file(const config::Set& set, const fs::path& base_dir, F&& f) {
  for (const config::Entry& e : set.entries) {
    if (e.is_set) {
      for_each_named_file(e.set, base_dir, f);
      continue;
    }
    if (e.value.kind != config::Value::Kind::Word && e.value.kind != config::Value::Kind::String) continue;
    const std::string& name = e.value.text;
    if (name.empty() || name.rfind("cgal:", 0) == 0) continue;
    fs::path p(name);
    if (p.is_relative()) p = base_dir / p;
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) f(e, p);
  }
}

}  // namespace

void JobContext::check_outputs() const {
  const config::Set& out = output_section();
  (void)word(out, "mesh", "ply", {"ply", "obj", "off", "stl", "none"});
  (void)flag(out, "lsg", true);
  (void)word(out, "method", "mc", {"mc", "nets"});

  const std::string prefix = stem(options_.name);
  const fs::path out_dir = options_.output_dir;
  for_each_named_file(root_, options_.base_dir, [&](const config::Entry& e, const fs::path& p) {
    const std::string file = p.filename().string();
    if (file.rfind(prefix, 0) != 0 || !is_output_extension(p)) return;
    std::error_code ec;
    if (!fs::equivalent(p.parent_path().empty() ? fs::path(".") : p.parent_path(), out_dir, ec) || ec) return;
    throw Error(ErrorCode::IoError, config::place_of(e, options_.name),
                "the input '" + file + "' is in the output directory under the job's output name '" + prefix +
                    "', where this job writes its results; refusing to risk overwriting it (choose another "
                    "output directory with -o, or rename the job file)");
  });
}

}  // namespace levelset::jobs
