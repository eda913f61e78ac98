#include "lib/job_inputs.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "lib/client_error.hpp"

namespace levelset::client {

namespace fs = std::filesystem;

namespace {

const char* const kFileKeys[][2] = {{"input", "mesh"},       {"input", "lsg"},           {"input", "points"},
                                    {"input", "sample_mesh"}, {"input", "image"},         {"csg.operand", "mesh"},
                                    {"csg.operand", "lsg"}};

const config::Set* find_set(const config::Set& root, const std::string& dotted) {
  const config::Set* s = &root;
  std::size_t start = 0;
  while (s != nullptr && start <= dotted.size()) {
    const std::size_t dot = std::min(dotted.find('.', start), dotted.size());
    const config::Entry* e = s->find(std::string_view(dotted).substr(start, dot - start));
    s = e != nullptr && e->is_set ? &e->set : nullptr;
    start = dot + 1;
  }
  return s;
}

bool looks_like_upload_id(const std::string& v) { return v.find("-u-") != std::string::npos && v.find('/') == std::string::npos; }

}  // namespace

std::vector<InputFile> job_input_files(const config::Set& job, const std::string& job_dir) {
  std::vector<InputFile> out;
  for (const auto& [section, key] : kFileKeys) {
    const config::Set* s = find_set(job, section);
    if (s == nullptr) continue;
    const config::Entry* e = s->find(key);
    if (e == nullptr || e->is_set) continue;
    InputFile f{std::string(section) + "." + key, e->value.text, ""};
    if (f.value.rfind("cgal:", 0) != 0) {
      fs::path p(f.value);
      if (p.is_relative()) p = fs::path(job_dir.empty() ? "." : job_dir) / p;
      std::error_code ec;
      if (fs::is_regular_file(p, ec)) {
        f.path = p.lexically_normal().string();
      } else if (!looks_like_upload_id(f.value)) {
        throw ClientError(ClientError::Kind::Local, "io_error",
                          "the job's " + f.key + " names no such file: " + p.string());
      }
    }
    out.push_back(f);
  }
  return out;
}

std::string upload_format_of(const std::string& file) {
  fs::path p(file);
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".gz") {
    ext = p.stem().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  }
  if (!ext.empty()) ext = ext.substr(1);
  static const char* const kKnown[] = {"off", "ply", "obj", "stl", "tria", "xyz", "xyzn", "pwn", "inr", "nrrd", "lsg"};
  for (const char* k : kKnown)
    if (ext == k) return ext;
  throw ClientError(ClientError::Kind::Usage, "unknown_format",
                    "cannot tell the upload format of '" + file +
                        "' from its extension (known: off ply obj stl tria xyz xyzn pwn inr nrrd lsg); give --format");
}

}  // namespace levelset::client
