// The input files a job file names, for `levelsetctl run`: found in the parsed job (after the
// --set overrides), resolved like `levelsetd run` resolves them (relative to the job file's
// directory; absolute paths as they are), uploaded once each, and replaced by their upload ids
// through extra "KEY=ID" overrides. "cgal:..." names and values that are already upload ids
// (no such local file) are left for the server to resolve.
//
// The keys that name input files (common/jobs: JobContext::input_path and input_band):
//   input.mesh input.lsg input.points input.sample_mesh input.image
//   csg.operand.mesh csg.operand.lsg
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "config/config_file.hpp"

namespace levelset::client {

struct InputFile {
  std::string key;    // "input.mesh"
  std::string value;  // as written ("meshes/knot.off")
  std::string path;   // the local file it names ("" when left to the server)
};

std::vector<InputFile> job_input_files(const config::Set& job, const std::string& job_dir);

// An upload format from a file name: the extension, lower-case (".gz" looks through: x.inr.gz
// -> inr); ClientError{Usage} when it is none the server knows.
std::string upload_format_of(const std::string& file);

}  // namespace levelset::client
