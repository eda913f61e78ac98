// The native .lsg file: one NarrowBand, compressed and checksummed.
//
// Layout (little-endian):
//   header, 128 bytes:
//     0  magic "\x89LSG\r\n\x1a\n"       8  u32 version (1)      12 u32 header bytes (128)
//     16 u32 value type (1 = float32)   20 u32 flags (bit 0: far_inside, bit 1: closest points)
//     24 f64 voxel size  32 f64[3] origin  56 f64 half-width (voxels)
//     64 u64 bricks  72 u64 active voxels  80 u64 payload bytes raw  88 u64 payload bytes stored
//     96..119 reserved (zero)           120 u64 XXH3-64 of bytes [0,120) and the stored payload
//   payload, zstd-compressed: brick coords (i32 x3 per brick), active masks (64 B per brick),
//     inside masks (64 B per brick), values (f32 per active voxel, byte-shuffled into 4 planes
//     so zstd sees slowly varying exponent bytes together); with flag bit 1, then the closest
//     surface point of every active voxel (all x, all y, all z as f32, byte-shuffled likewise).
// Reading checks, in order: size >= header, magic (UnsupportedFormat), version (newer:
// UnsupportedVersion), header fields, truncation (Truncated), checksum (Corrupt), counts and
// raw size against the limits, the compression ratio and the memory budget (LimitExceeded),
// then the payload as it streams out of zstd in small pieces: sorted unique bricks in range,
// mask popcounts never above the header's voxel count, finite values, signs agree (Corrupt).
// Resource bounds (a small file never costs much): the raw size may be at most
// max_compression_ratio times the stored size (plus 1 MiB), and what the decoded band will
// hold must fit memory_budget, both checked before decompressing anything; the decompressed
// payload is never held whole (pieces of ZSTD_DStreamOutSize()), bricks grow with what was
// decoded, and values are allocated only once the decoded masks confirm their count.
// Writing goes through write_file_atomically: a crash never leaves a half file.
// Cost: O(active voxels); zstd level 3 runs at a few hundred MB/s.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>
#include <string>
#include <string_view>

#include "core/memory_budget.hpp"
#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

inline constexpr std::uint32_t kLsgVersion = 1;

struct LsgWriteOptions {
  int compression_level = 3;  // zstd level, 1..19
  // Optional extra field: one closest surface point per active voxel, in band value order.
  std::span<const Vec3f> closest_points;
};

// Real bands written by levelsetd compress 1.4:1 (knot) to 3:1 (sphere) and up to ~900:1
// (the flat faces of a box at 2048^3, the most compressible shape measured); zstd itself cannot
// exceed ~32000:1. 4096 leaves a factor 4.5 of margin above the best real file.
inline constexpr double kLsgMaxCompressionRatio = 4096.0;
inline constexpr std::uint64_t kLsgRatioSlackBytes = std::uint64_t{1} << 20;

struct LsgReadOptions {
  std::uint64_t max_file_bytes = std::uint64_t{1} << 36;
  std::uint64_t max_active_voxels = (std::uint64_t{1} << 32) - 1;
  std::uint64_t max_raw_bytes = std::uint64_t{1} << 34;  // decompressed payload (16 GiB)
  // raw bytes <= max_compression_ratio * stored bytes + kLsgRatioSlackBytes
  double max_compression_ratio = kLsgMaxCompressionRatio;
  // Bytes the decode may hold at its peak (the file, the bricks, the values); see
  // core/memory_budget.hpp (levelsetd --memory-budget).
  std::uint64_t memory_budget = default_memory_budget();
  ProgressHook progress;
};

struct LsgHeader {
  std::uint32_t version = kLsgVersion;
  std::uint32_t value_type = 1;
  bool far_inside = false;
  bool closest_points = false;
  GridFrame frame;
  std::uint64_t bricks = 0;
  std::uint64_t active_voxels = 0;
  std::uint64_t raw_bytes = 0;
  std::uint64_t stored_bytes = 0;
};

struct LsgReadResult {
  NarrowBand band;
  LsgHeader header;
  std::uint64_t file_bytes = 0;
  std::vector<Vec3f> closest_points;  // empty unless the file carries them
};

struct LsgWriteResult {
  std::uint64_t file_bytes = 0;
  std::uint64_t raw_bytes = 0;
};

// What levelsetd info reports without keeping the values (summarize_lsg).
struct LsgSummary {
  LsgHeader header;
  std::uint64_t file_bytes = 0;
  std::uint64_t memory_bytes = 0;  // NarrowBand::memory_bytes() of the decoded band
  IndexBox active_index_bounds;    // NarrowBand::active_index_bounds() of the decoded band
};

// Encodes to bytes (what save_lsg writes).
std::string encode_lsg(const NarrowBand& band, const LsgWriteOptions& options = {});
LsgWriteResult save_lsg(const NarrowBand& band, const std::filesystem::path& path,
                        const LsgWriteOptions& options = {});

// name is used in error messages (a path or "upload").
LsgReadResult decode_lsg(std::string_view bytes, std::string_view name,
                         const LsgReadOptions& options = {});
LsgReadResult load_lsg(const std::filesystem::path& path, const LsgReadOptions& options = {});

// The same checks and errors as decode_lsg (the whole payload is streamed and validated), but
// only the bricks' coordinates and masks are kept, never the values: memory about 140 bytes
// per brick plus 2 bits per active voxel.
LsgSummary summarize_lsg(std::string_view bytes, std::string_view name, const LsgReadOptions& options = {});
LsgSummary summarize_lsg_file(const std::filesystem::path& path, const LsgReadOptions& options = {});

}  // namespace levelset
