// Fuzz target: the .lsg reader (decode_lsg).
//
// The first input byte picks a mode (byte % 3), the rest is the data:
//   0  the data is a file, decoded as is (magic, header and checksum checks);
//   1  the data is a file; when it holds a whole header, the checksum field is recomputed
//      first, so mutations get past the checksum to the frame, size and structure checks;
//   2  the data is a 128-byte header followed by a RAW (uncompressed) payload: the payload is
//      compressed with zstd, the stored-size field and the checksum are patched (the raw-size
//      field stays as given), so decompression and structure validation see fuzzed content.
// Only levelset::Error may leave decode_lsg; anything else escapes to the driver as a bug.
// summarize_lsg (what info reads) must accept exactly the files decode_lsg accepts, and
// describe them as the decoded band would (memory, bounds).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include <xxhash.h>
#include <zstd.h>

#include "core/error.hpp"
#include "grid/lsg_file.hpp"

namespace {

constexpr std::size_t kHeaderBytes = 128;
constexpr std::size_t kStoredSizeOffset = 88;
constexpr std::size_t kChecksumOffset = 120;

void put_u64(std::string& s, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) s[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

// XXH3-64 of bytes [0,120) and everything after the header, written at byte 120.
void reseal(std::string& file) {
  XXH3_state_t* st = XXH3_createState();
  XXH3_64bits_reset(st);
  XXH3_64bits_update(st, file.data(), kChecksumOffset);
  XXH3_64bits_update(st, file.data() + kHeaderBytes, file.size() - kHeaderBytes);
  put_u64(file, kChecksumOffset, XXH3_64bits_digest(st));
  XXH3_freeState(st);
}

// Header + zstd(raw payload); false when zstd refuses (it does not for any input size here).
bool compress_payload(std::string_view header_and_raw, std::string& file) {
  const std::string_view raw = header_and_raw.substr(kHeaderBytes);
  file.assign(header_and_raw.substr(0, kHeaderBytes));
  file.resize(kHeaderBytes + ZSTD_compressBound(raw.size()));
  const std::size_t n =
      ZSTD_compress(file.data() + kHeaderBytes, file.size() - kHeaderBytes, raw.data(), raw.size(), 1);
  if (ZSTD_isError(n)) return false;
  file.resize(kHeaderBytes + n);
  put_u64(file, kStoredSizeOffset, n);
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int mode = data[0] % 3;
  const std::string_view input(reinterpret_cast<const char*>(data) + 1, size - 1);

  levelset::LsgReadOptions options;
  options.max_raw_bytes = std::uint64_t{64} << 20;  // keep per-input allocations small
  options.memory_budget = std::uint64_t{256} << 20;

  std::string file;
  if (mode == 0 || input.size() < kHeaderBytes) {
    file.assign(input);
  } else if (mode == 1) {
    file.assign(input);
    reseal(file);
  } else {
    if (!compress_payload(input, file)) return 0;
    reseal(file);
  }

  // The summary (levelsetd info) refuses exactly what the decode refuses, and agrees on counts.
  bool summarized = false;
  levelset::LsgSummary summary;
  try {
    summary = levelset::summarize_lsg(file, "fuzz.lsg", options);
    summarized = true;
  } catch (const levelset::Error&) {
  }
  try {
    const levelset::LsgReadResult r = levelset::decode_lsg(file, "fuzz.lsg", options);
    if (!summarized || summary.header.bricks != r.header.bricks || summary.memory_bytes != r.band.memory_bytes() ||
        !(summary.active_index_bounds == r.band.active_index_bounds()))
      __builtin_trap();
    // A file the reader accepts must describe itself consistently and survive a round trip.
    if (r.band.active_voxel_count() != r.header.active_voxels ||
        r.band.brick_count() != r.header.bricks || r.file_bytes != file.size())
      __builtin_trap();
    const std::string again = levelset::encode_lsg(r.band);
    if (!levelset::decode_lsg(again, "fuzz-reencoded.lsg", options).band.identical(r.band))
      __builtin_trap();
  } catch (const levelset::Error&) {
  }
  return 0;
}
