// Resource bombs for the reader tests (issue 14): small files whose headers claim enormous
// payloads, built in memory in milliseconds.
//
//   zstd_rle_frame(n, byte)   a valid zstd frame of n copies of byte: RLE blocks of 128 KiB,
//                             4 bytes each (about 32000:1, zstd's ceiling)
//   lsg_bomb(bricks, voxels, payload)
//                             an .lsg file with a valid checksum whose header claims these
//                             counts (raw size consistent with them) over `payload`
//   lsg_brick_bomb()          64 KB claiming 15M empty bricks (2.1 GB of zeros)
//   lsg_voxel_bomb()          61 KB claiming 4M bricks and 2e9 active voxels (a 2 GB frame)
//   gzip_zeros(n)             gzip of n zero bytes (deflate's ~1000:1)
//   inr_gz_bomb(n)            an .inr.gz of an n^3 uint8 all-zero image (640: 255 KB)
//   nrrd_gz_bomb(n)           a .nrrd with gzip data of an n^3 uint8 all-zero image
#pragma once

#include <xxhash.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace levelset::test {

inline void append_le(std::string& s, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

inline std::string zstd_rle_frame(std::uint64_t n, unsigned char byte) {
  std::string f;
  append_le(f, 0xFD2FB528u, 4);  // magic
  f.push_back('\0');             // frame header descriptor: no content size, window descriptor follows
  f.push_back('\x38');           // window 2^17 (128 KiB)
  constexpr std::uint64_t kBlock = std::uint64_t{1} << 17;
  do {
    const std::uint64_t size = n < kBlock ? n : kBlock;
    n -= size;
    const std::uint32_t header = (n == 0 ? 1u : 0u) | (1u << 1) | std::uint32_t(size << 3);  // last, RLE, size
    append_le(f, header, 3);
    f.push_back(static_cast<char>(byte));
  } while (n > 0);
  return f;
}

inline std::string lsg_bomb(std::uint64_t bricks, std::uint64_t voxels, const std::string& payload) {
  std::string s("\x89LSG\r\n\x1a\n", 8);
  append_le(s, 1, 4);    // version
  append_le(s, 128, 4);  // header bytes
  append_le(s, 1, 4);    // float32
  append_le(s, 0, 4);    // flags
  const double frame[5] = {0.01, 0.0, 0.0, 0.0, 3.0};  // voxel size, origin, half-width
  for (double d : frame) {
    std::uint64_t u;
    std::memcpy(&u, &d, 8);
    append_le(s, u, 8);
  }
  append_le(s, bricks, 8);
  append_le(s, voxels, 8);
  append_le(s, bricks * 140 + voxels * 4, 8);
  append_le(s, payload.size(), 8);
  s.append(24, '\0');
  std::string covered = s + payload;
  const std::uint64_t sum = XXH3_64bits(covered.data(), covered.size());
  append_le(s, sum, 8);
  s += payload;
  return s;
}

inline std::string lsg_brick_bomb() {
  const std::uint64_t bricks = 15'000'000;
  return lsg_bomb(bricks, 0, zstd_rle_frame(bricks * 140, 0));
}

inline std::string lsg_voxel_bomb() {
  return lsg_bomb(4'000'000, 2'000'000'000, zstd_rle_frame(std::uint64_t{2} << 30, 0));
}

inline std::string gzip_zeros(std::uint64_t n, const std::string& prefix = {}) {
  z_stream z{};
  if (deflateInit2(&z, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) throw std::runtime_error("deflateInit2");
  std::vector<char> zeros(std::size_t{1} << 20, '\0');
  std::string out;
  std::vector<char> buf(std::size_t{1} << 16);
  auto pump = [&](const char* data, std::size_t size, int flush) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
    z.avail_in = static_cast<uInt>(size);
    do {
      z.next_out = reinterpret_cast<Bytef*>(buf.data());
      z.avail_out = static_cast<uInt>(buf.size());
      deflate(&z, flush);
      out.append(buf.data(), buf.size() - z.avail_out);
    } while (z.avail_out == 0 || (flush == Z_FINISH && z.avail_in > 0));
  };
  pump(prefix.data(), prefix.size(), Z_NO_FLUSH);
  while (n > 0) {
    const std::size_t k = std::size_t(n < zeros.size() ? n : zeros.size());
    n -= k;
    pump(zeros.data(), k, n == 0 ? Z_FINISH : Z_NO_FLUSH);
  }
  deflateEnd(&z);
  return out;
}

inline std::string inr_header(std::int64_t nx, std::int64_t ny, std::int64_t nz) {
  std::string h = "#INRIMAGE-4#{\nXDIM=" + std::to_string(nx) + "\nYDIM=" + std::to_string(ny) +
                  "\nZDIM=" + std::to_string(nz) + "\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nCPU=decm\n";
  h.append(252 - h.size(), '\n');
  return h + "##}\n";
}

inline std::string inr_gz_bomb(std::int64_t n) {
  return gzip_zeros(std::uint64_t(n) * std::uint64_t(n) * std::uint64_t(n), inr_header(n, n, n));
}

inline std::string nrrd_gz_bomb(std::int64_t n) {
  const std::string header = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " + std::to_string(n) + " " +
                             std::to_string(n) + " " + std::to_string(n) + "\nencoding: gzip\n\n";
  return header + gzip_zeros(std::uint64_t(n) * std::uint64_t(n) * std::uint64_t(n));
}

}  // namespace levelset::test
