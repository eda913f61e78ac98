// STL, ascii and binary; exactly equal coordinates are welded into one vertex.
#include "io/mesh_format_readers.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace levelset::detail {

namespace {

// Welds exactly equal coordinates (after mapping -0 to +0) into one vertex: open addressing
// on the bit patterns; table entries are vertex indices. The hash is seeded per process so that
// a crafted file cannot make every vertex collide (the output order does not depend on it).
class VertexWelder {
 public:
  // expected: a guess of the distinct vertices, to size the table once (it still grows).
  VertexWelder(std::vector<Vec3d>& out, std::uint64_t expected)
      : out_(out), table_(std::bit_ceil(std::max<std::uint64_t>(2 * expected, 1024)), kEmpty) {}

  // Index of p (appended if new); false when a new vertex would exceed limit.
  bool add(Vec3d p, std::uint64_t limit, std::uint32_t& index) {
    p = Vec3d{p.x + 0.0, p.y + 0.0, p.z + 0.0};
    const std::size_t mask = table_.size() - 1;
    std::size_t slot = hash(p) & mask;
    while (table_[slot] != kEmpty) {
      if (out_[table_[slot]] == p) {
        index = table_[slot];
        return true;
      }
      slot = (slot + 1) & mask;
    }
    if (out_.size() >= limit) return false;
    index = static_cast<std::uint32_t>(out_.size());
    out_.push_back(p);
    table_[slot] = index;
    if (out_.size() * 2 > table_.size()) grow();
    return true;
  }

 private:
  static constexpr std::uint32_t kEmpty = UINT32_MAX;

  static std::uint64_t seed() {
    static const std::uint64_t value = [] {
      std::random_device device;
      return (std::uint64_t{device()} << 32) ^ device();
    }();
    return value;
  }

  static std::size_t hash(const Vec3d& p) {
    std::uint64_t h = seed();
    for (const double c : {p.x, p.y, p.z}) {
      h = (h ^ std::bit_cast<std::uint64_t>(c)) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 32;
    }
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 29;
    return static_cast<std::size_t>(h);
  }

  void grow() {
    std::vector<std::uint32_t> bigger(table_.size() * 2, kEmpty);
    const std::size_t mask = bigger.size() - 1;
    for (std::uint32_t i = 0; i < out_.size(); ++i) {
      std::size_t slot = hash(out_[i]) & mask;
      while (bigger[slot] != kEmpty) slot = (slot + 1) & mask;
      bigger[slot] = i;
    }
    table_.swap(bigger);
  }

  std::vector<Vec3d>& out_;
  std::vector<std::uint32_t> table_;
};

}  // namespace

void read_stl_ascii(Reader& r) {
  r.result.format = MeshFormat::StlAscii;
  TextScanner sc(r.bytes, r.name);
  VertexWelder welder(r.result.mesh.vertices, 0);
  const auto expect = [&](std::string_view keyword) {
    const std::string_view tok = sc.next_token();
    if (tok.empty()) sc.fail_missing("'" + std::string(keyword) + "'");
    if (!iequals(tok, keyword))
      sc.fail(ErrorCode::ParseError,
              "expected '" + std::string(keyword) + "', found '" + TextScanner::quote(tok) + "'");
  };
  const auto where_fn = [&] { return sc.where(); };
  const auto fail_fn = [&](std::string reason) {
    sc.fail(ErrorCode::ParseError, std::move(reason));
  };
  expect("solid");
  sc.rest_of_line();  // the solid's name
  Fan fan;
  for (;;) {
    const std::string_view tok = sc.next_token();
    if (tok.empty()) sc.fail_missing("'facet' or 'endsolid'");
    if (iequals(tok, "endsolid")) {
      sc.rest_of_line();
      if (!sc.skip_to_token()) break;
      expect("solid");  // another solid follows
      sc.rest_of_line();
      continue;
    }
    if (!iequals(tok, "facet"))
      sc.fail(ErrorCode::ParseError,
              "expected 'facet' or 'endsolid', found '" + TextScanner::quote(tok) + "'");
    expect("normal");
    for (int k = 0; k < 3; ++k) sc.parse_any_number(sc.next_token(), "a facet normal component");
    expect("outer");
    expect("loop");
    for (;;) {
      const std::string_view vt = sc.next_token();
      if (vt.empty()) sc.fail_missing("'vertex' or 'endloop'");
      if (iequals(vt, "endloop")) break;
      if (!iequals(vt, "vertex"))
        sc.fail(ErrorCode::ParseError,
                "expected 'vertex' or 'endloop', found '" + TextScanner::quote(vt) + "'");
      Vec3d p;
      for (int k = 0; k < 3; ++k) p[k] = sc.parse_double(sc.next_token(), "a vertex coordinate");
      std::uint32_t index = 0;
      if (!welder.add(p, r.vertex_limit, index))
        sc.fail(ErrorCode::LimitExceeded,
                "more than " + std::to_string(r.vertex_limit) + " distinct vertices");
      fan.add(index, r, where_fn);
    }
    fan.finish(r, fail_fn);
    expect("endfacet");
    r.tick(sc.offset());
  }
}

void read_stl_binary(Reader& r) {
  r.result.format = MeshFormat::StlBinary;
  const std::uint64_t size = r.bytes.size();
  if (size < 84)
    throw Error(ErrorCode::Truncated, at_byte(r.name, size),
                "a binary STL needs an 84-byte header, found " + std::to_string(size) + " bytes");
  const std::uint64_t n = load_le32(r.bytes.data() + 80);
  if (n > r.options.max_triangles)
    throw Error(ErrorCode::LimitExceeded, at_byte(r.name, 80),
                "the file claims " + std::to_string(n) + " triangles, the limit is " +
                    std::to_string(r.options.max_triangles));
  const std::uint64_t expected = 84 + 50 * n;
  if (size < expected)
    throw Error(ErrorCode::Truncated, at_byte(r.name, 80),
                "the header claims " + std::to_string(n) + " triangles, which need " +
                    std::to_string(expected) + " bytes, but the file has " + std::to_string(size));
  if (size > expected)
    throw Error(ErrorCode::ParseError, at_byte(r.name, expected),
                std::to_string(size - expected) + " unexpected bytes after the last of the " +
                    std::to_string(n) + " triangles the header claims");
  auto& mesh = r.result.mesh;
  mesh.triangles.reserve(n);
  const std::uint64_t expected_vertices = std::min<std::uint64_t>(n / 2 + 3, r.vertex_limit);
  mesh.vertices.reserve(expected_vertices);
  VertexWelder welder(mesh.vertices, expected_vertices);
  for (std::uint64_t t = 0; t < n; ++t) {
    const std::uint64_t record = 84 + 50 * t;
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      Vec3d p;
      for (int a = 0; a < 3; ++a) {
        const std::uint64_t at =
            record + 12 + 12 * static_cast<std::uint64_t>(k) + 4 * static_cast<std::uint64_t>(a);
        const float value = std::bit_cast<float>(load_le32(r.bytes.data() + at));
        if (!std::isfinite(value))
          throw Error(ErrorCode::NonFinite, at_byte(r.name, at),
                      "triangle " + std::to_string(t) + " has a non-finite vertex coordinate");
        p[a] = static_cast<double>(value);
      }
      if (!welder.add(p, r.vertex_limit, tri[static_cast<std::size_t>(k)]))
        throw Error(ErrorCode::LimitExceeded, at_byte(r.name, record),
                    "more than " + std::to_string(r.vertex_limit) + " distinct vertices");
    }
    mesh.triangles.push_back(tri);
    r.tick(record);
  }
  r.result.source_faces = n;
}

}  // namespace levelset::detail
