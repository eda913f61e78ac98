// Resource bombs (issue 14): small files whose headers claim huge payloads must be refused (or
// described) cheaply. Each bomb is built here (tests/unit/bomb_files.hpp), then
//   - the real levelsetd runs on it in a child process (run_child): a clean typed error (exit
//     code 1, one "levelsetd: limit_exceeded at ..." line) or a header-only description, with
//     the child's peak RSS under 200 MB and its wall time under 5 s;
//   - the reader runs on it in process: the same error code and place, fast.
// Before the fix: the .lsg brick bomb (64 KB, 15M bricks) took 4.3 GB and 8-26 s in info, the
// voxel bomb (66 KB, 2e9 voxels) 2.1 GB; the 255 KB .inr.gz of a 640^3 zero image 1.05 GB in
// info and 6.15 GB (then ran for minutes) in segment.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "apps/segmentation.hpp"
#include "bomb_files.hpp"
#include "child_process.hpp"
#include "core/error.hpp"
#include "core/memory_budget.hpp"
#include "grid/lsg_file.hpp"
#include "io/image_reader.hpp"

namespace levelset {
namespace {

namespace fs = std::filesystem;

constexpr long kMaxPeakKb = 200 * 1024;  // 200 MB
constexpr double kMaxSeconds = 5.0;      // generous for a loaded 2-core machine

// Scratch directory: $LEVELSET_TMP/resource_bombs/<test>-<pid>, fresh for every test.
fs::path scratch_dir() {
  const char* env = std::getenv("LEVELSET_TMP");
  const fs::path base = env && *env ? fs::path(env) : fs::temp_directory_path() / "levelset-tests";
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = base / "resource_bombs" / (std::string(info->name()) + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

fs::path write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// levelsetd ARGS must fail with exit code 1 and one error line naming `code` and every piece
// of `mentions`, within the memory and time bounds.
void expect_clean_refusal(const std::vector<std::string>& args, const std::string& code,
                          const std::vector<std::string>& mentions) {
  std::vector<std::string> argv{test::levelsetd_path()};
  argv.insert(argv.end(), args.begin(), args.end());
  const test::ChildResult r = test::run_child(argv, 60.0);
  std::string cmd;
  for (const std::string& a : args) cmd += " " + a;
  SCOPED_TRACE("levelsetd" + cmd);
  EXPECT_FALSE(r.signaled) << "signal " << r.term_signal << (r.timed_out ? " (timed out)" : "");
  EXPECT_EQ(r.exit_code, 1) << r.stderr_text;
  EXPECT_EQ(r.stderr_text.rfind("levelsetd: " + code + " at ", 0), 0u) << r.stderr_text;
  EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
  for (const std::string& m : mentions) EXPECT_NE(r.stderr_text.find(m), std::string::npos) << m << " in " << r.stderr_text;
  EXPECT_LT(r.peak_rss_kb, kMaxPeakKb) << "peak RSS " << r.peak_rss_kb << " KB";
  EXPECT_LT(r.seconds, kMaxSeconds);
  testing::Test::RecordProperty("peak_rss_kb", std::to_string(r.peak_rss_kb));
  testing::Test::RecordProperty("seconds", std::to_string(r.seconds));
}

// ---------------------------------------------------------------------------------------------
// The helper itself.

TEST(ChildProcess, ReportsExitCodeOutputsRssAndTime) {
  const test::ChildResult ok = test::run_child({"/bin/sh", "-c", "echo out; echo err >&2; exit 3"}, 10);
  EXPECT_EQ(ok.exit_code, 3);
  EXPECT_FALSE(ok.signaled);
  EXPECT_EQ(ok.stdout_text, "out\n");
  EXPECT_EQ(ok.stderr_text, "err\n");
  EXPECT_GT(ok.peak_rss_kb, 0);
  EXPECT_LT(ok.seconds, 5.0);
  const test::ChildResult slow = test::run_child({"/bin/sleep", "10"}, 0.3);
  EXPECT_TRUE(slow.signaled);
  EXPECT_TRUE(slow.timed_out);
  EXPECT_LT(slow.seconds, 5.0);
  const test::ChildResult missing = test::run_child({"/nonexistent/program"}, 1);
  EXPECT_EQ(missing.exit_code, 127);
  EXPECT_FALSE(missing.stderr_text.empty());
  const test::ChildResult version = test::run_child({test::levelsetd_path(), "--version"}, 10);
  EXPECT_EQ(version.exit_code, 0) << version.stderr_text;
  EXPECT_EQ(version.stdout_text.rfind("levelsetd ", 0), 0u);
}

// ---------------------------------------------------------------------------------------------
// .lsg

TEST(LsgBombs, BricksClaimedBySixtyFourKilobytes) {
  const fs::path dir = scratch_dir();
  const std::string bomb = test::lsg_brick_bomb();
  ASSERT_LT(bomb.size(), 70'000u);
  const fs::path file = write_file(dir / "bricks.lsg", bomb);
  expect_clean_refusal({"info", file.string()}, "limit_exceeded", {"bricks.lsg @ byte 80", "ratio"});
  // Every command that reads a band goes through the same reader.
  expect_clean_refusal({"measure", file.string()}, "limit_exceeded", {"ratio"});
  expect_clean_refusal({"mesh", file.string(), "-o", (dir / "m.ply").string()}, "limit_exceeded", {"ratio"});
  EXPECT_FALSE(fs::exists(dir / "m.ply"));
  fs::remove_all(dir);
}

TEST(LsgBombs, ActiveVoxelsClaimedBySixtyFiveKilobytes) {
  const fs::path dir = scratch_dir();
  const std::string bomb = test::lsg_voxel_bomb();
  ASSERT_LT(bomb.size(), 70'000u);
  const fs::path file = write_file(dir / "voxels.lsg", bomb);
  expect_clean_refusal({"info", file.string()}, "limit_exceeded", {"voxels.lsg @ byte 80", "ratio"});
  fs::remove_all(dir);
}

TEST(LsgBombs, ReaderRefusesBeforeDecompressing) {
  for (const std::string& bomb : {test::lsg_brick_bomb(), test::lsg_voxel_bomb()}) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      (void)decode_lsg(bomb, "bomb.lsg");
      ADD_FAILURE() << "bomb accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
      EXPECT_EQ(e.where(), "bomb.lsg @ byte 80");
    }
    try {
      (void)summarize_lsg(bomb, "bomb.lsg");
      ADD_FAILURE() << "bomb accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
    }
    EXPECT_LT(seconds_since(t0), 0.5);
  }
}

// With the ratio and the budget lifted, the streamed structure checks still stop the brick
// bomb at its second brick (all coordinates zero), after one 128 KiB piece: the reader never
// holds the 2.1 GB it claims.
TEST(LsgBombs, StructureStopsALiftedBombAtOnce) {
  LsgReadOptions lifted;
  lifted.max_compression_ratio = std::numeric_limits<double>::infinity();
  lifted.memory_budget = std::numeric_limits<std::uint64_t>::max();
  const std::string bomb = test::lsg_brick_bomb();
  const auto t0 = std::chrono::steady_clock::now();
  for (int summary = 0; summary < 2; ++summary) {
    try {
      if (summary) (void)summarize_lsg(bomb, "bomb.lsg", lifted);
      else (void)decode_lsg(bomb, "bomb.lsg", lifted);
      ADD_FAILURE() << "bomb accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Corrupt) << e.what();
      EXPECT_EQ(e.where(), "bomb.lsg @ payload byte 12") << e.what();
    }
  }
  EXPECT_LT(seconds_since(t0), 0.5);

  // Sorted, in-range coordinates but full masks: the popcounts pass the header's voxel count
  // at the first brick (the masks follow 15M coordinates: 180 MB of streaming, no allocation
  // beyond the bricks decoded).
  const std::uint64_t bricks = 2000;
  std::string raw;
  for (std::uint64_t i = 0; i < bricks; ++i) test::append_le(raw, i, 4), test::append_le(raw, 0, 4), test::append_le(raw, 0, 4);
  raw.append(bricks * 64, '\xff');
  raw.append(bricks * 64, '\0');
  std::string stored(ZSTD_compressBound(raw.size()), '\0');
  stored.resize(ZSTD_compress(stored.data(), stored.size(), raw.data(), raw.size(), 3));
  std::string file = test::lsg_bomb(bricks, 0, stored);
  try {
    (void)decode_lsg(file, "masks.lsg", lifted);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Corrupt) << e.what();
    EXPECT_EQ(e.where(), "masks.lsg @ byte 72") << e.what();
    EXPECT_NE(e.reason().find("brick 0"), std::string::npos) << e.what();
  }
}

TEST(LsgBombs, MemoryBudgetRefusesBeforeDecoding) {
  const fs::path dir = scratch_dir();
  const fs::path file = dir / "sphere.lsg";
  const test::ChildResult made = test::run_child(
      {test::levelsetd_path(), "primitive", "sphere", "--resolution", "64", "-o", file.string()}, 60);
  ASSERT_EQ(made.exit_code, 0) << made.stderr_text;
  const std::string bytes = [&] {
    std::ifstream in(file, std::ios::binary);
    return std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }();
  LsgReadOptions tight;
  tight.memory_budget = 100'000;
  for (int summary = 0; summary < 2; ++summary) {
    try {
      if (summary) (void)summarize_lsg(bytes, "sphere.lsg", tight);
      else (void)decode_lsg(bytes, "sphere.lsg", tight);
      ADD_FAILURE() << "the budget was ignored";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
      EXPECT_EQ(e.where(), "sphere.lsg @ byte 64");
      EXPECT_NE(e.reason().find("--memory-budget"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW((void)decode_lsg(bytes, "sphere.lsg"));
  // The CLI flag sets it for every command.
  expect_clean_refusal({"--memory-budget", "100K", "info", file.string()}, "limit_exceeded",
                       {"memory budget of 100.0 KiB", "--memory-budget"});
  const test::ChildResult ok = test::run_child({test::levelsetd_path(), "--memory-budget", "1G", "info", file.string()}, 60);
  EXPECT_EQ(ok.exit_code, 0) << ok.stderr_text;
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Images

class ImageBombs : public testing::TestWithParam<const char*> {};

std::string image_bomb(const std::string& kind, std::int64_t n) {
  return kind == "inr" ? test::inr_gz_bomb(n) : test::nrrd_gz_bomb(n);
}

TEST_P(ImageBombs, InfoReadsTheHeaderOnly) {
  const std::string kind = GetParam();
  const fs::path dir = scratch_dir();
  const std::string bomb = image_bomb(kind, 640);
  ASSERT_LT(bomb.size(), 300'000u);
  const fs::path file = write_file(dir / (kind == "inr" ? "zeros.inr.gz" : "zeros.nrrd"), bomb);
  const test::ChildResult r = test::run_child({test::levelsetd_path(), "info", file.string()}, 60);
  EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_NE(r.stdout_text.find("640 x 640 x 640"), std::string::npos) << r.stdout_text;
  EXPECT_NE(r.stdout_text.find("not scanned"), std::string::npos) << r.stdout_text;
  EXPECT_LT(r.peak_rss_kb, kMaxPeakKb);
  EXPECT_LT(r.seconds, kMaxSeconds);
  testing::Test::RecordProperty("peak_rss_kb", std::to_string(r.peak_rss_kb));
  const test::ChildResult j = test::run_child({test::levelsetd_path(), "info", "--json", file.string()}, 60);
  EXPECT_EQ(j.exit_code, 0) << j.stderr_text;
  EXPECT_NE(j.stdout_text.find("\"range\": null"), std::string::npos) << j.stdout_text;
  EXPECT_LT(j.peak_rss_kb, kMaxPeakKb);
  fs::remove_all(dir);
}

TEST_P(ImageBombs, SegmentChecksTheBudgetBeforeReadingSamples) {
  const std::string kind = GetParam();
  const fs::path dir = scratch_dir();
  const fs::path file = write_file(dir / (kind == "inr" ? "zeros.inr.gz" : "zeros.nrrd"), image_bomb(kind, 640));
  expect_clean_refusal({"segment", file.string(), "--seed", "320,320,320", "-o", (dir / "out.lsg").string()},
                       "limit_exceeded", {"640 x 640 x 640", "memory budget", "--memory-budget"});
  EXPECT_FALSE(fs::exists(dir / "out.lsg"));
  // The segment job: the same check, downsampling counted (4x would fit: 160^3).
  const fs::path job = write_file(dir / "seg.conf", "job = segment\ninput {\n  image = " + file.filename().string() +
                                                        "\n}\nsegment {\n  seeds = (320, 320, 320)\n  steps = 1\n}\n");
  expect_clean_refusal({"run", job.string(), "-q", "-o", (dir / "out").string()}, "limit_exceeded",
                       {"640 x 640 x 640", "--memory-budget"});
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Gzip, ImageBombs, testing::Values("inr", "nrrd"));

TEST(ImageBombReader, SkipDescribesWithoutInflating) {
  const std::string bomb = test::inr_gz_bomb(640);
  const auto t0 = std::chrono::steady_clock::now();
  ImageReadOptions skip;
  skip.samples = ImageSamples::Skip;
  const ImageReadResult r = read_image_from_memory(bomb, "zeros.inr.gz", skip);
  EXPECT_LT(seconds_since(t0), 0.2);
  EXPECT_EQ(r.image.nx, 640);
  EXPECT_EQ(r.image.nz, 640);
  EXPECT_TRUE(r.image.samples.empty());
  EXPECT_TRUE(r.gzip);
  EXPECT_EQ(r.sample_type, "uint8");
  // Load: the samples (1 GiB as floats) are checked against the budget before inflating.
  ImageReadOptions load;
  load.memory_budget = std::uint64_t{256} << 20;
  try {
    (void)read_image_from_memory(bomb, "zeros.inr.gz", load);
    ADD_FAILURE() << "the budget was ignored";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
    EXPECT_NE(e.reason().find("--memory-budget"), std::string::npos) << e.what();
  }
  EXPECT_LT(seconds_since(t0), 0.5);
}

TEST(ImageBombReader, ScanAgreesWithLoadAndSkipStillChecksPlainLengths) {
  std::string inr = test::inr_header(4, 3, 2);
  for (int i = 0; i < 24; ++i) inr.push_back(static_cast<char>(10 + 3 * i));
  ImageReadOptions scan;
  scan.samples = ImageSamples::Scan;
  const ImageReadResult loaded = read_image_from_memory(inr, "a.inr");
  const ImageReadResult scanned = read_image_from_memory(inr, "a.inr", scan);
  EXPECT_EQ(loaded.image.samples.size(), 24u);
  EXPECT_TRUE(scanned.image.samples.empty());
  EXPECT_EQ(scanned.min_sample, loaded.min_sample);
  EXPECT_EQ(scanned.max_sample, loaded.max_sample);
  EXPECT_EQ(scanned.min_sample, 10.0f);
  EXPECT_EQ(scanned.max_sample, 79.0f);
  ImageReadOptions skip;
  skip.samples = ImageSamples::Skip;
  EXPECT_NO_THROW((void)read_image_from_memory(inr, "a.inr", skip));
  const std::string cut = inr.substr(0, inr.size() - 1);
  for (const ImageReadOptions& o : {skip, scan, ImageReadOptions{}}) {
    try {
      (void)read_image_from_memory(cut, "a.inr", o);
      ADD_FAILURE() << "truncated data accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Truncated) << e.what();
      EXPECT_EQ(e.where(), "a.inr @ byte 279") << e.what();
    }
  }
}

TEST(SegmentationBudget, EstimateFollowsTheImageAndNamesTheFlag) {
  ImageVolume shape;
  shape.nx = shape.ny = shape.nz = 640;
  apps::SegmentationOptions o;
  const std::uint64_t big = apps::segmentation_memory_bytes(shape, o);
  EXPECT_GT(big, std::uint64_t(20) * 640 * 640 * 640);  // 5 floats per voxel at least
  shape.nx = shape.ny = shape.nz = 64;
  const std::uint64_t small = apps::segmentation_memory_bytes(shape, o);
  EXPECT_LT(small, big / 100);
  o.label_mask = true;
  EXPECT_GT(apps::segmentation_memory_bytes(shape, o), small);
  o.memory_budget = small;
  try {
    apps::require_segmentation_budget(shape, 1000, o, "img.nrrd");
    ADD_FAILURE() << "the budget was ignored";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
    EXPECT_EQ(e.where(), "img.nrrd");
    EXPECT_NE(e.reason().find("64 x 64 x 64"), std::string::npos) << e.what();
    EXPECT_NE(e.reason().find("--memory-budget"), std::string::npos) << e.what();
  }
  o.memory_budget = default_memory_budget();
  EXPECT_NO_THROW(apps::require_segmentation_budget(shape, 1000, o, "img.nrrd"));
}

TEST(SegmentationBudget, TheFlagRaisesAndLowersIt) {
  const fs::path dir = scratch_dir();
  // A 24^3 image with a bright cube: small enough for any budget above a few MB.
  std::string inr = test::inr_header(24, 24, 24);
  for (int k = 0; k < 24; ++k)
    for (int j = 0; j < 24; ++j)
      for (int i = 0; i < 24; ++i)
        inr.push_back((i >= 6 && i < 18 && j >= 6 && j < 18 && k >= 6 && k < 18) ? '\xc8' : '\0');
  const fs::path file = write_file(dir / "cube.inr", inr);
  const std::vector<std::string> args = {"segment", file.string(), "--seed", "12,12,12", "--steps", "2",
                                         "-o", (dir / "out.lsg").string()};
  std::vector<std::string> tight = {"--memory-budget", "64K"};
  tight.insert(tight.end(), args.begin(), args.end());
  expect_clean_refusal(tight, "limit_exceeded", {"24 x 24 x 24", "memory budget of 64.0 KiB"});
  std::vector<std::string> argv = {test::levelsetd_path(), "--memory-budget", "512M"};
  argv.insert(argv.end(), args.begin(), args.end());
  const test::ChildResult r = test::run_child(argv, 60);
  EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_TRUE(fs::exists(dir / "out.lsg"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace levelset
