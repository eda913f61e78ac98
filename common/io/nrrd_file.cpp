#include "io/nrrd_file.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "core/file_io.hpp"

namespace levelset {

namespace {

static_assert(std::endian::native == std::endian::little, "the NRRD writer assumes a little-endian host");

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;

template <typename T>
std::string encode(const NrrdFrame& f, std::span<const T> samples, const char* type) {
  const std::uint64_t n = std::uint64_t(f.sizes[0]) * std::uint64_t(f.sizes[1]) * std::uint64_t(f.sizes[2]);
  if (samples.size() != n)
    throw Error(ErrorCode::InvalidArgument, "encode_nrrd", "sample count does not match the sizes");
  char head[1024];
  const double h = f.spacing;
  std::snprintf(head, sizeof head,
                "NRRD0004\n# levelset dense grid\ntype: %s\ndimension: 3\nsizes: %d %d %d\nspace dimension: 3\n"
                "space directions: (%.17g,0,0) (0,%.17g,0) (0,0,%.17g)\nspace origin: (%.17g,%.17g,%.17g)\n"
                "endian: little\nencoding: raw\n\n",
                type, f.sizes[0], f.sizes[1], f.sizes[2], h, h, h, f.origin.x, f.origin.y, f.origin.z);
  std::string out(head);
  const std::size_t at = out.size();
  out.resize(at + samples.size_bytes());
  if (!samples.empty()) std::memcpy(out.data() + at, samples.data(), samples.size_bytes());
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Numbers of a field value; separators are spaces, tabs, commas and parentheses.
std::vector<double> numbers(std::string_view v, const std::string& where) {
  std::vector<double> out;
  std::size_t i = 0;
  while (i < v.size()) {
    const char c = v[i];
    if (c == ' ' || c == '\t' || c == ',' || c == '(' || c == ')') {
      ++i;
      continue;
    }
    double x = 0;
    const auto [p, ec] = std::from_chars(v.data() + i, v.data() + v.size(), x);
    if (ec != std::errc() || p == v.data() + i) throw Error(ErrorCode::ParseError, where, "expected a number");
    if (!std::isfinite(x)) throw Error(ErrorCode::NonFinite, where, "not finite");
    out.push_back(x);
    i = std::size_t(p - v.data());
    if (out.size() > 64) throw Error(ErrorCode::ParseError, where, "too many numbers");
  }
  return out;
}

struct TypeInfo {
  const char* canonical;
  int bytes;
};

bool type_of(std::string_view t, TypeInfo& info) {
  struct Alias {
    const char* name;
    TypeInfo info;
  };
  static const Alias aliases[] = {
      {"signed char", {"int8", 1}}, {"int8", {"int8", 1}}, {"int8_t", {"int8", 1}},
      {"uchar", {"uint8", 1}}, {"unsigned char", {"uint8", 1}}, {"uint8", {"uint8", 1}}, {"uint8_t", {"uint8", 1}},
      {"short", {"int16", 2}}, {"short int", {"int16", 2}}, {"signed short", {"int16", 2}}, {"int16", {"int16", 2}},
      {"int16_t", {"int16", 2}}, {"ushort", {"uint16", 2}}, {"unsigned short", {"uint16", 2}},
      {"uint16", {"uint16", 2}}, {"uint16_t", {"uint16", 2}}, {"int", {"int32", 4}}, {"signed int", {"int32", 4}},
      {"int32", {"int32", 4}}, {"int32_t", {"int32", 4}}, {"uint", {"uint32", 4}}, {"unsigned int", {"uint32", 4}},
      {"uint32", {"uint32", 4}}, {"uint32_t", {"uint32", 4}}, {"float", {"float", 4}}, {"double", {"double", 8}}};
  for (const Alias& a : aliases)
    if (t == a.name) {
      info = a.info;
      return true;
    }
  return false;
}

template <typename T>
double read_as(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return double(v);
}

}  // namespace

std::string encode_nrrd(const NrrdFrame& frame, std::span<const std::int32_t> samples) {
  return encode(frame, samples, "int32");
}
std::string encode_nrrd(const NrrdFrame& frame, std::span<const float> samples) {
  return encode(frame, samples, "float");
}
void save_nrrd(const std::filesystem::path& path, const NrrdFrame& frame, std::span<const std::int32_t> samples) {
  write_file_atomically(path, encode_nrrd(frame, samples));
}
void save_nrrd(const std::filesystem::path& path, const NrrdFrame& frame, std::span<const float> samples) {
  write_file_atomically(path, encode_nrrd(frame, samples));
}

NrrdVolume decode_nrrd(std::string_view bytes, std::string_view name, std::uint64_t max_voxels) {
  const std::string file(name);
  if (bytes.size() < 9 || bytes.substr(0, 7) != "NRRD000" || bytes[7] < '1' || bytes[7] > '5' || bytes[8] != '\n')
    throw Error(ErrorCode::UnsupportedFormat, file, "not a NRRD file (magic NRRD0001..NRRD0005 expected)");
  NrrdVolume vol;
  TypeInfo type{nullptr, 0};
  bool have_sizes = false, have_dimension = false, have_encoding = false, little = false, have_endian = false;
  std::size_t pos = 9, line_no = 1, data_start = 0;
  for (;;) {
    ++line_no;
    if (pos >= bytes.size()) throw Error(ErrorCode::Truncated, at_line(file, line_no), "header ends without a blank line");
    const std::size_t nl = bytes.find('\n', pos);
    if (nl == std::string_view::npos || nl > kMaxHeaderBytes)
      throw Error(nl == std::string_view::npos ? ErrorCode::Truncated : ErrorCode::LimitExceeded,
                  at_line(file, line_no), "header line without end or header over 64 KiB");
    const std::string_view line = trim(bytes.substr(pos, nl - pos));
    pos = nl + 1;
    if (line.empty()) {
      data_start = pos;
      break;
    }
    if (line.front() == '#') continue;
    const std::string where = at_line(file, line_no);
    std::size_t colon = line.find(":=");
    if (colon != std::string_view::npos) continue;  // key/value pairs: ignored
    colon = line.find(':');
    if (colon == std::string_view::npos) throw Error(ErrorCode::ParseError, where, "expected 'field: value'");
    const std::string_view key = trim(line.substr(0, colon)), value = trim(line.substr(colon + 1));
    if (key == "type") {
      if (!type_of(value, type)) throw Error(ErrorCode::UnsupportedFormat, where, "unsupported type '" + std::string(value) + "'");
      vol.type = type.canonical;
    } else if (key == "dimension") {
      if (value != "3") throw Error(ErrorCode::UnsupportedFormat, where, "only 3-dimensional volumes are read");
      have_dimension = true;
    } else if (key == "sizes") {
      const std::vector<double> s = numbers(value, where);
      if (s.size() != 3) throw Error(ErrorCode::ParseError, where, "expected 3 sizes");
      for (int a = 0; a < 3; ++a) {
        if (!(s[a] >= 1 && s[a] <= double(1 << 30) && s[a] == std::floor(s[a])))
          throw Error(ErrorCode::ParseError, where, "sizes must be integers in [1, 2^30]");
        vol.frame.sizes[a] = int(s[a]);
      }
      have_sizes = true;
    } else if (key == "encoding") {
      if (value != "raw") throw Error(ErrorCode::UnsupportedFormat, where, "only raw encoding is read");
      have_encoding = true;
    } else if (key == "endian") {
      if (value != "little" && value != "big") throw Error(ErrorCode::ParseError, where, "endian must be little or big");
      little = value == "little";
      have_endian = true;
    } else if (key == "spacings") {
      const std::vector<double> s = numbers(value, where);
      if (s.size() != 3 || !(s[0] > 0) || s[0] != s[1] || s[0] != s[2])
        throw Error(ErrorCode::UnsupportedFormat, where, "three equal positive spacings expected (cubic voxels)");
      vol.frame.spacing = s[0];
    } else if (key == "space directions") {
      const std::vector<double> d = numbers(value, where);
      if (d.size() != 9 || !(d[0] > 0) || d[0] != d[4] || d[0] != d[8] || d[1] != 0 || d[2] != 0 || d[3] != 0 ||
          d[5] != 0 || d[6] != 0 || d[7] != 0)
        throw Error(ErrorCode::UnsupportedFormat, where, "axis-aligned cubic voxels expected: (h,0,0) (0,h,0) (0,0,h)");
      vol.frame.spacing = d[0];
    } else if (key == "space origin") {
      const std::vector<double> o = numbers(value, where);
      if (o.size() != 3) throw Error(ErrorCode::ParseError, where, "expected 3 coordinates");
      vol.frame.origin = {o[0], o[1], o[2]};
    } else if (key == "data file" || key == "datafile") {
      throw Error(ErrorCode::UnsupportedFormat, where, "detached data files are not read");
    }
  }
  if (!type.canonical || !have_dimension || !have_sizes || !have_encoding)
    throw Error(ErrorCode::ParseError, file, "header lacks type, dimension, sizes or encoding");
  if (type.bytes > 1 && (!have_endian || !little))
    throw Error(ErrorCode::UnsupportedFormat, file, "multi-byte samples must be little-endian");
  const std::uint64_t n =
      std::uint64_t(vol.frame.sizes[0]) * std::uint64_t(vol.frame.sizes[1]) * std::uint64_t(vol.frame.sizes[2]);
  if (n > max_voxels)
    throw Error(ErrorCode::LimitExceeded, file, std::to_string(n) + " samples exceed the limit " + std::to_string(max_voxels));
  const std::uint64_t need = n * std::uint64_t(type.bytes), have = bytes.size() - data_start;
  if (have < need)
    throw Error(ErrorCode::Truncated, at_byte(file, bytes.size()), "data holds " + std::to_string(have) +
                                                                    " bytes, the header needs " + std::to_string(need));
  if (have > need) throw Error(ErrorCode::Corrupt, at_byte(file, data_start + need), "bytes after the samples");
  vol.samples.resize(std::size_t(n));
  const char* p = bytes.data() + data_start;
  const std::string_view t = type.canonical;
  const int kind = t == "int8" ? 0 : t == "uint8" ? 1 : t == "int16" ? 2 : t == "uint16" ? 3 : t == "int32" ? 4
                 : t == "uint32" ? 5 : t == "float" ? 6 : 7;
  for (std::size_t i = 0; i < vol.samples.size(); ++i, p += type.bytes) {
    double v = 0;
    switch (kind) {
      case 0: v = read_as<std::int8_t>(p); break;
      case 1: v = read_as<std::uint8_t>(p); break;
      case 2: v = read_as<std::int16_t>(p); break;
      case 3: v = read_as<std::uint16_t>(p); break;
      case 4: v = read_as<std::int32_t>(p); break;
      case 5: v = read_as<std::uint32_t>(p); break;
      case 6: v = read_as<float>(p); break;
      default: v = read_as<double>(p); break;
    }
    if (std::isnan(v)) throw Error(ErrorCode::NonFinite, at_byte(file, std::uint64_t(p - bytes.data())), "NaN sample");
    vol.samples[i] = v;
  }
  return vol;
}

NrrdVolume load_nrrd(const std::filesystem::path& path, std::uint64_t max_voxels) {
  return decode_nrrd(read_file_bytes(path, std::min<std::uint64_t>(max_voxels, std::uint64_t{1} << 56) * 8 + kMaxHeaderBytes), path.string(), max_voxels);
}

}  // namespace levelset
