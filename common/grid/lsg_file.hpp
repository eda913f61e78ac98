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
// UnsupportedVersion), header fields, truncation (Truncated), checksum (Corrupt), payload size
// and structure (sorted unique bricks, popcounts, finite values, signs agree: Corrupt).
// Allocation is bounded by the bytes actually decompressed, never by a header count alone.
// Writing goes through write_file_atomically: a crash never leaves a half file.
// Cost: O(active voxels); zstd level 3 runs at a few hundred MB/s.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>
#include <string>
#include <string_view>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

inline constexpr std::uint32_t kLsgVersion = 1;

struct LsgWriteOptions {
  int compression_level = 3;  // zstd level, 1..19
  // Optional extra field: one closest surface point per active voxel, in band value order.
  std::span<const Vec3f> closest_points;
};

struct LsgReadOptions {
  std::uint64_t max_file_bytes = std::uint64_t{1} << 36;
  std::uint64_t max_active_voxels = (std::uint64_t{1} << 32) - 1;
  std::uint64_t max_raw_bytes = std::uint64_t{1} << 34;  // decompressed payload (16 GiB)
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

// Encodes to bytes (what save_lsg writes).
std::string encode_lsg(const NarrowBand& band, const LsgWriteOptions& options = {});
LsgWriteResult save_lsg(const NarrowBand& band, const std::filesystem::path& path,
                        const LsgWriteOptions& options = {});

// name is used in error messages (a path or "upload").
LsgReadResult decode_lsg(std::string_view bytes, std::string_view name,
                         const LsgReadOptions& options = {});
LsgReadResult load_lsg(const std::filesystem::path& path, const LsgReadOptions& options = {});

}  // namespace levelset
