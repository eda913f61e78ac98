// Batch subcommands of levelsetd. Each takes plain arguments (parsed by main.cpp with
// CLI11), runs the same core functions the daemon uses, prints to stdout and returns
// the process exit code. Errors propagate as levelset::Error; main.cpp prints them.
#pragma once

#include <string>

namespace levelset::cli {

struct InfoArgs {
  std::string path;
  bool json = false;
};
int run_info(const InfoArgs& args);

struct PrimitiveArgs {
  std::string shape;
  int resolution = 256;
  double band = 3.0;
  std::string output;
  int threads = 0;
  std::string stats;
};
int run_primitive(const PrimitiveArgs& args);

}  // namespace levelset::cli
