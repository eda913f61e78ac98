// levelsetd sample IN.lsg --points P.xyz [-o OUT.txt]: interpolated values at points.
#include <cstdio>
#include <string>

#include "commands/commands.hpp"
#include "core/file_io.hpp"
#include "grid/interpolate.hpp"
#include "grid/lsg_file.hpp"
#include "io/point_cloud_reader.hpp"

namespace levelset::cli {

int run_sample(const SampleArgs& args) {
  const LsgReadResult level_set = load_lsg(args.input);
  const PointCloud points = read_point_cloud(args.points).cloud;
  BandAccessor accessor(level_set.band);
  std::string out;
  out.reserve(points.points.size() * 14);
  char line[64];
  for (const Vec3d& p : points.points) {
    const int n = std::snprintf(line, sizeof line, "%.9g\n", sample_trilinear(accessor, level_set.band, p));
    out.append(line, std::size_t(n));
  }
  if (args.output.empty() || args.output == "-") {
    std::fwrite(out.data(), 1, out.size(), stdout);
  } else {
    write_file_atomically(args.output, out);
    std::printf("%zu values -> %s\n", points.points.size(), args.output.c_str());
  }
  return 0;
}

}  // namespace levelset::cli
