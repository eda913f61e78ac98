// NRRD (.nrrd with attached data, .nhdr with a detached data file): "NRRD000N" magic, then
// "field: value" lines up to a blank line; raw or gzip encoding. See image_reader.hpp.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/image_format_readers.hpp"

namespace levelset::detail {

namespace {

constexpr std::size_t kMaxHeader = std::size_t{1} << 20;

SampleType parse_type(const std::string& t, const std::string& where) {
  static const std::map<std::string, SampleType, std::less<>> kTypes = {
      {"signed char", SampleType::Int8}, {"int8", SampleType::Int8}, {"int8_t", SampleType::Int8},
      {"uchar", SampleType::UInt8}, {"unsigned char", SampleType::UInt8}, {"uint8", SampleType::UInt8},
      {"uint8_t", SampleType::UInt8},
      {"short", SampleType::Int16}, {"short int", SampleType::Int16}, {"signed short", SampleType::Int16},
      {"signed short int", SampleType::Int16}, {"int16", SampleType::Int16}, {"int16_t", SampleType::Int16},
      {"ushort", SampleType::UInt16}, {"unsigned short", SampleType::UInt16},
      {"unsigned short int", SampleType::UInt16}, {"uint16", SampleType::UInt16}, {"uint16_t", SampleType::UInt16},
      {"int", SampleType::Int32}, {"signed int", SampleType::Int32}, {"int32", SampleType::Int32},
      {"int32_t", SampleType::Int32},
      {"uint", SampleType::UInt32}, {"unsigned int", SampleType::UInt32}, {"uint32", SampleType::UInt32},
      {"uint32_t", SampleType::UInt32},
      {"longlong", SampleType::Int64}, {"long long", SampleType::Int64}, {"long long int", SampleType::Int64},
      {"signed long long", SampleType::Int64}, {"signed long long int", SampleType::Int64},
      {"int64", SampleType::Int64}, {"int64_t", SampleType::Int64},
      {"ulonglong", SampleType::UInt64}, {"unsigned long long", SampleType::UInt64},
      {"unsigned long long int", SampleType::UInt64}, {"uint64", SampleType::UInt64},
      {"uint64_t", SampleType::UInt64},
      {"float", SampleType::Float32}, {"double", SampleType::Float64}};
  const auto it = kTypes.find(t);
  if (it == kTypes.end()) throw Error(ErrorCode::UnsupportedFormat, where, "type '" + t + "'");
  return it->second;
}

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

// "(a,b,c)" -> a b c
Vec3d parse_vector(std::string_view s, const std::string& where, std::string_view what) {
  s = trim(s);
  if (s.size() < 2 || s.front() != '(' || s.back() != ')')
    throw Error(ErrorCode::ParseError, where, std::string(what) + ": expected (x,y,z), got '" + std::string(s) + "'");
  s = s.substr(1, s.size() - 2);
  Vec3d v;
  for (int a = 0; a < 3; ++a) {
    const std::size_t comma = s.find(',');
    if ((a < 2) != (comma != std::string_view::npos))
      throw Error(ErrorCode::ParseError, where, std::string(what) + ": expected three components");
    v[a] = parse_real(s.substr(0, comma), where, what);
    s = a < 2 ? s.substr(comma + 1) : std::string_view{};
  }
  return v;
}

// Vectors "(..) (..) (..)" (or "none" for non-spatial axes).
std::vector<std::string_view> split_vectors(std::string_view s) {
  std::vector<std::string_view> out;
  for (std::string_view w : words(s)) out.push_back(w);
  return out;
}

}  // namespace

ImageReadResult read_nrrd(std::string_view bytes, std::string_view name, const ImageReadOptions& options,
                          const DataFileLoader& load_data_file) {
  if (bytes.size() < 8 || bytes.substr(0, 7) != "NRRD000" || bytes[7] < '1' || bytes[7] > '5')
    throw Error(ErrorCode::UnsupportedFormat, at_line(name, 1), "not a NRRD file (no NRRD0001..NRRD0005 magic)");
  // Header: lines up to the first empty one (or the end, for a detached header).
  std::map<std::string, std::pair<std::string, std::uint64_t>, std::less<>> fields;
  std::size_t pos = 0;
  std::uint64_t line_no = 0;
  bool ended = false;
  while (pos < bytes.size()) {
    if (pos > kMaxHeader) throw Error(ErrorCode::LimitExceeded, at_line(name, line_no), "NRRD header longer than 1 MiB");
    std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string_view::npos) eol = bytes.size();
    if (eol - pos > kMaxHeader) throw Error(ErrorCode::LimitExceeded, at_line(name, line_no + 1), "NRRD header line longer than 1 MiB");
    std::string_view line = bytes.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = std::min(bytes.size(), eol + 1);
    ++line_no;
    if (line_no == 1) continue;
    if (line.empty()) {
      ended = true;
      break;
    }
    if (line.front() == '#') continue;
    if (line.find(":=") != std::string_view::npos) continue;  // key/value pairs
    const std::size_t colon = line.find(": ");
    if (colon == std::string_view::npos || colon == 0)
      throw Error(ErrorCode::ParseError, at_line(name, line_no),
                  "expected 'field: value', got '" + std::string(line.substr(0, 60)) + "'");
    std::string key(trim(line.substr(0, colon)));
    std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (key == "datafile") key = "data file";
    if (key == "byteskip") key = "byte skip";
    if (key == "lineskip") key = "line skip";
    if (fields.count(key)) throw Error(ErrorCode::ParseError, at_line(name, line_no), "repeated field '" + key + "'");
    fields.emplace(std::move(key), std::make_pair(std::string(trim(line.substr(colon + 2))), line_no));
  }
  const std::uint64_t header_bytes = pos;
  auto where_of = [&](std::string_view key) {
    const auto it = fields.find(key);
    return it == fields.end() ? at_line(name, line_no) : at_line(name, it->second.second);
  };
  auto text = [&](std::string_view key) -> const std::string* {
    const auto it = fields.find(key);
    return it == fields.end() ? nullptr : &it->second.first;
  };
  auto required = [&](std::string_view key) -> const std::string& {
    const std::string* v = text(key);
    if (!v) throw Error(ErrorCode::ParseError, at_line(name, line_no), "NRRD header has no '" + std::string(key) + "' field");
    return *v;
  };

  SampleLayout layout;
  layout.type = parse_type(required("type"), where_of("type"));
  const std::int64_t dim = parse_dimension(required("dimension"), where_of("dimension"), "dimension");
  if (dim < 1 || dim > 3)
    throw Error(ErrorCode::UnsupportedFormat, where_of("dimension"), "dimension " + std::to_string(dim) + " (only 1 to 3)");
  const std::vector<std::string_view> sizes = words(required("sizes"));
  if (std::int64_t(sizes.size()) != dim)
    throw Error(ErrorCode::ParseError, where_of("sizes"), "sizes has " + std::to_string(sizes.size()) + " entries for dimension " + std::to_string(dim));
  std::int64_t n[3] = {1, 1, 1};
  for (std::int64_t a = 0; a < dim; ++a) {
    n[a] = parse_dimension(sizes[std::size_t(a)], where_of("sizes"), "size");
    if (n[a] <= 0) throw Error(ErrorCode::ParseError, where_of("sizes"), "sizes must be positive");
  }
  layout.nx = n[0];
  layout.ny = n[1];
  layout.nz = n[2];

  const std::string& encoding = required("encoding");
  bool gzip = false;
  if (encoding == "gzip" || encoding == "gz") gzip = true;
  else if (encoding != "raw")
    throw Error(ErrorCode::UnsupportedFormat, where_of("encoding"), "encoding '" + encoding + "' (only raw and gzip)");
  if (const std::string* endian = text("endian")) {
    if (*endian == "big") layout.big_endian = true;
    else if (*endian != "little") throw Error(ErrorCode::ParseError, where_of("endian"), "endian must be little or big, got '" + *endian + "'");
  } else if (sample_size(layout.type) > 1) {
    throw Error(ErrorCode::ParseError, at_line(name, line_no), "NRRD header has no 'endian' field for multi-byte samples");
  }

  ImageReadResult result;
  result.format = ImageFormat::Nrrd;
  Vec3d spacing{1, 1, 1}, origin{};
  if (const std::string* s = text("spacings")) {
    const std::vector<std::string_view> w = words(*s);
    if (std::int64_t(w.size()) != dim) throw Error(ErrorCode::ParseError, where_of("spacings"), "spacings needs " + std::to_string(dim) + " entries");
    for (std::int64_t a = 0; a < dim; ++a) {
      spacing[int(a)] = parse_real(w[std::size_t(a)], where_of("spacings"), "spacing");
      if (spacing[int(a)] <= 0) throw Error(ErrorCode::ParseError, where_of("spacings"), "spacings must be positive");
    }
  }
  if (const std::string* s = text("space directions")) {
    if (text("spacings")) throw Error(ErrorCode::ParseError, where_of("space directions"), "both 'spacings' and 'space directions'");
    const std::vector<std::string_view> w = split_vectors(*s);
    if (std::int64_t(w.size()) != dim) throw Error(ErrorCode::ParseError, where_of("space directions"), "space directions needs " + std::to_string(dim) + " vectors");
    for (std::int64_t a = 0; a < dim; ++a) {
      const Vec3d d = parse_vector(w[std::size_t(a)], where_of("space directions"), "space direction");
      for (int b = 0; b < 3; ++b)
        if ((b == a && d[b] <= 0) || (b != a && d[b] != 0))
          throw Error(ErrorCode::UnsupportedFormat, where_of("space directions"),
                      "only axis-aligned space directions with positive steps are supported");
      spacing[int(a)] = d[int(a)];
    }
  }
  if (const std::string* s = text("space origin")) origin = parse_vector(*s, where_of("space origin"), "space origin");
  result.image.spacing = spacing;
  result.image.origin = origin;
  check_image_limits(layout, options, where_of("sizes"));

  std::int64_t byte_skip = 0, line_skip = 0;
  if (const std::string* s = text("byte skip")) {
    byte_skip = parse_dimension(*s, where_of("byte skip"), "byte skip");
    if (byte_skip < -1 || (byte_skip == -1 && gzip))
      throw Error(ErrorCode::ParseError, where_of("byte skip"), "byte skip must be >= 0 (or -1 with raw encoding)");
  }
  if (const std::string* s = text("line skip")) {
    line_skip = parse_dimension(*s, where_of("line skip"), "line skip");
    if (line_skip < 0) throw Error(ErrorCode::ParseError, where_of("line skip"), "line skip must be >= 0");
  }

  // The data: after the header, or in the detached file.
  std::string detached;
  std::string_view data;
  std::string data_name(name);
  std::uint64_t data_base = header_bytes;
  if (const std::string* file = text("data file")) {
    if (file->empty() || file->rfind("LIST", 0) == 0 || file->find('%') != std::string::npos || words(*file).size() != 1)
      throw Error(ErrorCode::UnsupportedFormat, where_of("data file"), "only a single detached data file is supported");
    if (!load_data_file)
      throw Error(ErrorCode::UnsupportedFormat, where_of("data file"), "detached data file '" + *file + "' cannot be read from memory");
    detached = load_data_file(*file);
    data = detached;
    data_name = *file;
    data_base = 0;
    result.detached = true;
  } else {
    if (!ended) throw Error(ErrorCode::Truncated, at_line(name, line_no), "NRRD header does not end with a blank line");
    data = bytes.substr(header_bytes);
  }
  for (std::int64_t l = 0; l < line_skip; ++l) {
    const std::size_t eol = data.find('\n');
    if (eol == std::string_view::npos) throw Error(ErrorCode::Truncated, at_byte(data_name, data_base + data.size()), "line skip runs past the data");
    data.remove_prefix(eol + 1);
    data_base += eol + 1;
  }
  const std::uint64_t raw_bytes = layout.nx * layout.ny * std::uint64_t(layout.nz) * sample_size(layout.type);
  if (!gzip) {
    if (byte_skip == -1) {
      if (data.size() < raw_bytes)
        throw Error(ErrorCode::Truncated, at_byte(data_name, data_base), "data hold " + std::to_string(data.size()) + " bytes, " + std::to_string(raw_bytes) + " expected");
      byte_skip = std::int64_t(data.size() - raw_bytes);
    }
    if (std::uint64_t(byte_skip) > data.size())
      throw Error(ErrorCode::Truncated, at_byte(data_name, data_base + data.size()), "byte skip runs past the data");
    data.remove_prefix(std::size_t(byte_skip));
    data_base += std::uint64_t(byte_skip);
    if (data.size() < raw_bytes)
      throw Error(ErrorCode::Truncated, at_byte(data_name, data_base + data.size()),
                  "data hold " + std::to_string(data.size()) + " bytes, " + std::to_string(raw_bytes) + " expected");
    ByteStream stream(data, false, data_name);
    read_samples(stream, layout, data_base, data_name, options, result);
  } else {
    ByteStream stream(data, true, data_name);
    std::vector<char> skip(4096);
    // (Skip: nothing is inflated, not even the skipped bytes.)
    for (std::int64_t left = options.samples == ImageSamples::Skip ? 0 : byte_skip; left > 0;) {
      const std::size_t want = std::size_t(std::min<std::int64_t>(left, 4096));
      if (stream.read(skip.data(), want) < want)
        throw Error(ErrorCode::Truncated, at_byte(data_name, stream.position()) + " (decompressed)", "byte skip runs past the data");
      left -= std::int64_t(want);
    }
    read_samples(stream, layout, std::uint64_t(byte_skip), data_name + " (decompressed)", options, result);
  }
  result.gzip = gzip;
  result.file_bytes = bytes.size() + detached.size();
  return result;
}

}  // namespace levelset::detail
