#include "distance/redistance_domain.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "grid/band_builder.hpp"

namespace levelset::detail {

namespace {

// ---------------------------------------------------------------------------------------
// Brick-mask morphology: one-voxel dilation along one axis, across brick faces.
// Mask layout (brick_mask.hpp): word = z-slice, byte = y-row, bit = x.
constexpr std::uint64_t kCol0 = 0x0101010101010101ull;  // x = 0
constexpr std::uint64_t kCol7 = 0x8080808080808080ull;  // x = 7
constexpr std::uint64_t kRow0 = 0x00000000000000ffull;  // y = 0
constexpr std::uint64_t kRow7 = 0xff00000000000000ull;  // y = 7

bool face_layer_set(const BrickMask& m, int axis, bool plus) {
  if (axis == 2) return m.words[plus ? 7 : 0] != 0;
  const std::uint64_t sel = axis == 0 ? (plus ? kCol7 : kCol0) : (plus ? kRow7 : kRow0);
  for (std::uint64_t w : m.words)
    if (w & sel) return true;
  return false;
}

BrickMask dilate_along(const BrickMask& m, const BrickMask* minus, const BrickMask* plus, int axis) {
  BrickMask r;
  for (int w = 0; w < 8; ++w) {
    std::uint64_t v = m.words[w];
    if (axis == 0) {
      v |= ((v << 1) & ~kCol0) | ((v >> 1) & ~kCol7);
      if (minus) v |= (minus->words[w] & kCol7) >> 7;
      if (plus) v |= (plus->words[w] & kCol0) << 7;
    } else if (axis == 1) {
      v |= (v << 8) | (v >> 8);
      if (minus) v |= minus->words[w] >> 56;
      if (plus) v |= plus->words[w] << 56;
    } else {
      if (w > 0) v |= m.words[w - 1];
      else if (minus) v |= minus->words[7];
      if (w < 7) v |= m.words[w + 1];
      else if (plus) v |= plus->words[0];
    }
    r.words[w] = v;
  }
  return r;
}

// Bricks sorted by key with one mask each; lookups by binary search.
struct BrickSet {
  std::vector<Coord> coords;
  std::vector<std::uint64_t> keys;
  std::vector<BrickMask> masks;

  std::uint32_t find(const Coord& c) const {
    if (!brick_in_range(c)) return kNoBrick;
    const std::uint64_t k = brick_key(c);
    const auto it = std::lower_bound(keys.begin(), keys.end(), k);
    return it != keys.end() && *it == k ? std::uint32_t(it - keys.begin()) : kNoBrick;
  }
};

Coord unit(int axis, int s) {
  Coord d{0, 0, 0};
  d[axis] = s;
  return d;
}

// One-voxel dilation of every mask along `axis` (both directions), allocating bricks the
// dilation reaches.
void dilate_once(BrickSet& set, int axis) {
  std::vector<Coord> extra;
  for (std::size_t b = 0; b < set.coords.size(); ++b) {
    for (int s = -1; s <= 1; s += 2) {
      if (!face_layer_set(set.masks[b], axis, s > 0)) continue;
      const Coord c = set.coords[b] + unit(axis, s);
      if (!brick_in_range(c))
        throw Error(ErrorCode::LimitExceeded, "redistance",
                    "growing the band leaves the index range");
      if (set.find(c) == kNoBrick) extra.push_back(c);
    }
  }
  if (!extra.empty()) {
    std::sort(extra.begin(), extra.end(),
              [](const Coord& a, const Coord& b) { return brick_key(a) < brick_key(b); });
    extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
    if (set.coords.size() + extra.size() > kMaxBricks)
      throw Error(ErrorCode::LimitExceeded, "redistance", "domain exceeds 2^23 bricks");
    BrickSet merged;
    const std::size_t n = set.coords.size() + extra.size();
    merged.coords.reserve(n);
    merged.keys.reserve(n);
    merged.masks.reserve(n);
    std::size_t i = 0, j = 0;
    while (i < set.coords.size() || j < extra.size()) {
      const bool take_old =
          j == extra.size() || (i < set.coords.size() && set.keys[i] < brick_key(extra[j]));
      if (take_old) {
        merged.coords.push_back(set.coords[i]);
        merged.keys.push_back(set.keys[i]);
        merged.masks.push_back(set.masks[i]);
        ++i;
      } else {
        merged.coords.push_back(extra[j]);
        merged.keys.push_back(brick_key(extra[j]));
        merged.masks.push_back(BrickMask{});
        ++j;
      }
    }
    set = std::move(merged);
  }
  std::vector<BrickMask> out(set.coords.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, set.coords.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t b = r.begin(); b != r.end(); ++b) {
                        const std::uint32_t lo = set.find(set.coords[b] + unit(axis, -1));
                        const std::uint32_t hi = set.find(set.coords[b] + unit(axis, 1));
                        out[b] = dilate_along(set.masks[b], lo == kNoBrick ? nullptr : &set.masks[lo],
                                              hi == kNoBrick ? nullptr : &set.masks[hi], axis);
                      }
                    });
  set.masks = std::move(out);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The domain: the input's bricks, their active voxels dilated by `grow` voxels.
RedistanceDomain build_domain(const NarrowBand& in, int grow, const ProgressHook& progress) {
  BrickSet set;
  const auto bricks = in.bricks();
  set.coords.reserve(bricks.size());
  for (const Brick& br : bricks) {
    set.coords.push_back(br.coord);
    set.keys.push_back(brick_key(br.coord));
    set.masks.push_back(br.active);
  }
  for (int k = 0; k < grow; ++k) {
    for (int axis = 0; axis < 3; ++axis) dilate_once(set, axis);
    progress.check("redistance");
  }
  if (set.coords.size() > kMaxBricks)
    throw Error(ErrorCode::LimitExceeded, "redistance", "domain exceeds 2^23 bricks");

  RedistanceDomain w;
  const std::size_t n = set.coords.size();
  w.coords = set.coords;
  w.domain = std::move(set.masks);
  w.nbr.resize(n);
  w.source.resize(n);
  w.fixed.assign(n, BrickMask{});
  w.inside.resize(n);
  w.dist.resize(n * kBrickVoxels);  // uninitialised: each brick's part is filled below, in parallel
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      std::fill_n(w.values(std::uint32_t(b)), kBrickVoxels, kInf);
      const Coord c = set.coords[b];
      for (int f = 0; f < 6; ++f) w.nbr[b][f] = set.find(c + unit(f >> 1, (f & 1) ? 1 : -1));
      const std::uint32_t src = grow == 0 ? std::uint32_t(b) : in.find_brick(c);
      w.source[b] = src;
      if (src != kNoBrick) {
        w.inside[b] = in.inside_mask(src);
        continue;
      }
      // A brick the input does not have: one sign per x-row (NarrowBand's row rule).
      BrickMask m;
      const Coord o = brick_origin(c);
      for (int z = 0; z < kBrickDim; ++z)
        for (int y = 0; y < kBrickDim; ++y)
          if (in.is_inside_unallocated(o + Coord{0, y, z})) m.words[z] |= std::uint64_t{0xff} << (8 * y);
      w.inside[b] = m;
    }
  });
  return w;
}

// ---------------------------------------------------------------------------------------
// Output: voxels with distance <= W (voxels), signed by the input, in a new band.
NarrowBand assemble_band(const NarrowBand& in, const RedistanceDomain& w, const GridFrame& frame) {
  const std::size_t n = w.size();
  const double limit = frame.half_width;
  const double h = frame.voxel_size;
  std::vector<BrickMask> active(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const float* d = w.values(std::uint32_t(b));
      BrickMask m = w.fixed[b];
      w.domain[b].for_each_set([&](int v) {
        if (double(d[v]) <= limit) m.set(v);
      });
      active[b] = m;
    }
  });
  // Bricks without active voxels are uniform in sign (band invariant) and dropped; the
  // output's row rule then gives their sign from the nearest kept brick of their x-row,
  // which is right because no sign change lies in between. A brick row with no kept brick
  // falls back to far_inside: keep one brick there when its sign differs.
  std::vector<std::uint8_t> keep(n, 0);
  for (std::size_t b = 0; b < n;) {
    std::size_t e = b;
    bool any = false;
    while (e < n && w.coords[e].y == w.coords[b].y && w.coords[e].z == w.coords[b].z) {
      keep[e] = !active[e].none();
      any |= keep[e] != 0;
      ++e;
    }
    if (!any && w.inside[b].test(0) != in.far_inside()) keep[b] = 1;
    b = e;
  }
  BandBuilder builder(frame);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    alignas(64) float dense[kBrickVoxels];
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      if (!keep[b]) continue;
      const float* d = w.values(std::uint32_t(b));
      active[b].for_each_set([&](int v) {
        const float mag = static_cast<float>(double(d[v]) * h);
        // Inside voxels stay strictly negative (a -0 would read as outside).
        dense[v] = w.inside[b].test(v) ? -std::max(mag, std::numeric_limits<float>::min()) : mag;
      });
      builder.add_brick(w.coords[b], active[b], w.inside[b], dense);
    }
  });
  return builder.finish(in.far_inside());
}

}  // namespace levelset::detail
