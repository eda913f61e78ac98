// Job files (common/jobs): a small job end to end through run_job, and every error kind of
// the shared sections with its place and reason.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "core/error.hpp"
#include "io/image_reader.hpp"
#include "jobs/job.hpp"

namespace levelset::jobs {

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir() {
  const char* env = std::getenv("LEVELSET_TMP");
  const fs::path base = env && *env ? fs::path(env) : fs::temp_directory_path() / "levelset-tests";
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = base / "jobs" / (std::string(info->name()) + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

JobResult run_text(const std::string& text, const fs::path& dir, std::vector<std::string> overrides = {},
                   bool confine = false) {
  const fs::path job = dir / "test.conf";
  std::ofstream(job) << text;
  JobOptions options;
  options.output_dir = (dir / "out").string();
  options.confine_inputs = confine;
  return run_job_file(job.string(), overrides, options);
}

// The error a job raises: its code, where and reason (fails the test when none is thrown).
Error error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no error thrown";
  return Error(ErrorCode::InvalidArgument, "", "");
}

const char* kSphereJob = R"(// a sphere grows at speed 1
job = evolve
input { shape = sphere }
raster { resolution = 32 }
evolve {
  speed = c
  constants { c = 1 }
  time = 0.1
}
)";

}  // namespace

TEST(Jobs, SmallJobRunsEndToEndAndWritesItsOutputs) {
  const fs::path dir = scratch_dir();
  const JobResult r = run_text(kSphereJob, dir);
  EXPECT_EQ(r.application, "evolve");
  for (const char* ext : {".lsg", ".ply", ".log", ".stats.json"}) {
    const fs::path p = dir / "out" / (std::string("test") + ext);
    EXPECT_TRUE(fs::exists(p)) << p;
    EXPECT_GT(fs::file_size(p), 0u) << p;
  }
  EXPECT_EQ(r.outputs.size(), 4u);
  // The built-in sphere (radius 1) grew by t * speed = 0.1: the volume says so.
  const double volume = r.stats["mesh"]["volume"];
  const double radius = std::cbrt(3 * volume / (4 * M_PI));
  EXPECT_NEAR(radius, 1.1, 0.01);
  EXPECT_EQ(r.stats["evolution"]["stop"], "completed");
  EXPECT_TRUE(r.stats["mesh"]["watertight"]);
  std::ifstream log(dir / "out" / "test.log");
  std::string all((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(all.find("input: built-in sphere"), std::string::npos) << all;
  EXPECT_NE(all.find("done in"), std::string::npos) << all;
}

TEST(Jobs, OverridesChangeTheRunAndOutputsCanBeSwitchedOff) {
  const fs::path dir = scratch_dir();
  const JobResult r = run_text(kSphereJob, dir, {"evolve.time=0.2", "output.mesh=none", "output.lsg=no"});
  EXPECT_FALSE(fs::exists(dir / "out" / "test.ply"));
  EXPECT_FALSE(fs::exists(dir / "out" / "test.lsg"));
  EXPECT_EQ(r.outputs.size(), 2u);  // log and stats
  EXPECT_NEAR(static_cast<double>(r.stats["evolution"]["time"]), 0.2, 1e-12);
}

TEST(Jobs, ErrorsNameThePlaceAndTheReason) {
  const fs::path dir = scratch_dir();
  const std::string job = (dir / "test.conf").string();
  struct Case {
    std::string text;
    std::vector<std::string> overrides;
    ErrorCode code;
    std::string where, reason;  // where: a suffix of e.where() (an entry's key); reason: a substring
  };
  const std::vector<Case> cases = {
      {"input { shape = sphere }\n", {}, ErrorCode::InvalidArgument, "test.conf", "starts with 'job = NAME'"},
      {"job = evolv\n", {}, ErrorCode::InvalidArgument, "test.conf:1:1", "did you mean 'evolve'"},
      {"job = evolve\nimput { }\n", {}, ErrorCode::InvalidArgument, "test.conf:2:1", "did you mean 'input'"},
      {"job = evolve\ninput = sphere\n", {}, ErrorCode::InvalidArgument, "test.conf:2:1", "must be a set"},
      // Two entries on one line (issue 14): both read, and the pair refused as on two lines.
      {"job = evolve\ninput { shape = sphere mesh = a.off }\n", {}, ErrorCode::InvalidArgument, "test.conf",
       "exactly one of"},
      {"job = evolve\ninput { shape = sphere\n mesh = a.off }\n", {}, ErrorCode::InvalidArgument, "test.conf",
       "exactly one of"},
      {"job = evolve\ninput { shape = cube }\n", {}, ErrorCode::InvalidArgument, "test.conf:2:9", "not one of"},
      {"job = evolve\ninput { shape = sphere }\nraster { resolution = 4 }\n", {}, ErrorCode::InvalidArgument,
       "test.conf:3:10", "outside"},
      {"job = evolve\ninput { shape = sphere }\nraster { resolution = (1, 2) }\n", {}, ErrorCode::InvalidArgument,
       "test.conf:3:10", "must be a number"},
      {"job = evolve\ninput { shape = sphere }\nraster { resolution = 32.5 }\n", {}, ErrorCode::InvalidArgument,
       "test.conf:3:10", "whole number"},
      {"job = evolve\ninput { mesh = missing.off }\n", {}, ErrorCode::IoError, "test.conf:2:9", "no such file"},
      {"job = evolve\ninput { mesh = \"cgal:../../etc/passwd\" }\n", {}, ErrorCode::InvalidArgument,
       "test.conf:2:9", "'..'"},
      {"job = evolve\ninput { mesh = \"cgal:/etc/passwd\" }\n", {}, ErrorCode::InvalidArgument, "test.conf:2:9",
       "cgal: names are relative"},
      {"job = evolve\ninput { shape = sphere }\nraster { band = 64 }\n", {}, ErrorCode::InvalidArgument,
       "test.conf:3:10", "outside"},
      {"job = evolve\ninput { shape = sphere }\nraster { resolution = 32 }\nevolve { speed = 1+ \n time = 1 }\n",
       {}, ErrorCode::ParseError, "test.conf:4:10 (formula:column 3)", "expected a value"},
      {"job = evolve\ninput { shape = sphere }\nraster { resolution = 32 }\nevolve { speed = 1\n }\n", {},
       ErrorCode::InvalidArgument, "test.conf", "exactly one of 'steps' and 'time'"},
      {kSphereJob, {"evolve.tiem=1"}, ErrorCode::InvalidArgument, "--set evolve.tiem=1", "did you mean 'time'"},
      {kSphereJob, {"evolve.scheme=weno7"}, ErrorCode::InvalidArgument, "--set evolve.scheme=weno7", "not one of"},
  };
  for (const Case& c : cases) {
    const Error e = error_of([&] { run_text(c.text, dir, c.overrides); });
    EXPECT_EQ(e.code(), c.code) << c.text << " -> " << e.what();
    EXPECT_TRUE(e.where().size() >= c.where.size() &&
                e.where().compare(e.where().size() - c.where.size(), c.where.size(), c.where) == 0)
        << c.text << " -> where '" << e.where() << "', expected '..." << c.where << "'";
    EXPECT_NE(e.reason().find(c.reason), std::string::npos) << c.text << " -> " << e.reason();
  }
}

TEST(Jobs, ConfinedInputsCannotLeaveTheJobDirectory) {
  const fs::path dir = scratch_dir();
  fs::create_directories(dir / "inner");
  std::ofstream(dir / "outside.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const fs::path job = dir / "inner" / "test.conf";
  std::ofstream(job) << "job = evolve\ninput { mesh = ../outside.off }\nevolve { speed = 1\n steps = 1 }\n";
  JobOptions options;
  options.output_dir = (dir / "out").string();
  options.confine_inputs = true;
  const Error e = error_of([&] { run_job_file(job.string(), {}, options); });
  EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
  EXPECT_NE(e.reason().find("leaves the job's directory"), std::string::npos) << e.what();
  std::ofstream(dir / "inner" / "abs.conf") << "job = evolve\ninput { mesh = " << (dir / "outside.off").string()
                                             << " }\nevolve { speed = 1\n steps = 1 }\n";
  const Error e2 = error_of([&] { run_job_file((dir / "inner" / "abs.conf").string(), {}, options); });
  EXPECT_NE(e2.reason().find("leaves the job's directory"), std::string::npos) << e2.what();
}

TEST(Jobs, DetachedImageDataStaysBesideItsHeader) {
  // A NRRD header must not make the reader open a file outside its folder.
  const fs::path dir = scratch_dir();
  fs::create_directories(dir / "inner");
  std::ofstream(dir / "outside.raw", std::ios::binary) << std::string(8, '\0');
  std::ofstream(dir / "inside.raw", std::ios::binary) << std::string(8, '\0');
  const std::string head = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: ";
  for (const std::string& target : {std::string("../outside.raw"), (dir / "outside.raw").string()}) {
    std::ofstream(dir / "inner" / "x.nhdr") << head << target << "\n\n";
    const Error e = error_of([&] { read_image(dir / "inner" / "x.nhdr"); });
    EXPECT_EQ(e.code(), ErrorCode::UnsupportedFormat) << target << ": " << e.what();
    EXPECT_NE(e.reason().find("header's folder"), std::string::npos) << e.what();
  }
  fs::copy_file(dir / "inside.raw", dir / "inner" / "inside.raw");
  std::ofstream(dir / "inner" / "x.nhdr") << head << "inside.raw\n\n";
  EXPECT_EQ(read_image(dir / "inner" / "x.nhdr").image.voxel_count(), 8u);
}

}  // namespace levelset::jobs
