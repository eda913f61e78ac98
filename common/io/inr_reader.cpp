// INRIMAGE-4 (.inr, .inr.gz): a text header of KEY=VALUE lines from "#INRIMAGE-4#{" to "##}",
// then raw samples. See image_reader.hpp for the fields read.
#include <map>
#include <string>

#include "core/error.hpp"
#include "io/image_format_readers.hpp"

namespace levelset::detail {

namespace {

constexpr std::string_view kMagic = "#INRIMAGE-4#{";
constexpr std::string_view kEnd = "##}\n";
constexpr std::size_t kMaxHeader = std::size_t{1} << 20;

// The header text up to and including "##}\n"; bytes read beyond it are given back.
std::string read_header(ByteStream& stream, std::string_view name) {
  std::string header;
  char chunk[256];
  while (true) {
    const std::size_t searched_from = header.size() >= kEnd.size() ? header.size() - kEnd.size() + 1 : 0;
    const std::size_t got = stream.read(chunk, sizeof chunk);
    header.append(chunk, got);
    if (header.size() >= kMagic.size() && header.compare(0, kMagic.size(), kMagic) != 0)
      throw Error(ErrorCode::UnsupportedFormat, at_line(name, 1), "not an INRIMAGE-4 file (no '#INRIMAGE-4#{')");
    const std::size_t end = header.find(kEnd, searched_from);
    if (end != std::string::npos) {
      const std::size_t data = end + kEnd.size();
      stream.unread(std::string_view(header).substr(data));
      header.resize(data);
      return header;
    }
    if (got < sizeof chunk) {
      if (header.size() < kMagic.size())
        throw Error(ErrorCode::Truncated, at_byte(name, header.size()), "file ends inside the INR magic");
      throw Error(ErrorCode::Truncated, at_byte(name, header.size()), "INR header has no end marker '##}'");
    }
    if (header.size() > kMaxHeader)
      throw Error(ErrorCode::LimitExceeded, at_byte(name, kMaxHeader), "INR header longer than 1 MiB");
  }
}

SampleType sample_type(std::string_view type, std::int64_t bits, const std::string& where) {
  if (type == "float") {
    if (bits == 32) return SampleType::Float32;
    if (bits == 64) return SampleType::Float64;
  } else if (type == "unsigned fixed") {
    switch (bits) {
      case 8: return SampleType::UInt8;
      case 16: return SampleType::UInt16;
      case 32: return SampleType::UInt32;
      case 64: return SampleType::UInt64;
    }
  } else if (type == "signed fixed") {
    switch (bits) {
      case 8: return SampleType::Int8;
      case 16: return SampleType::Int16;
      case 32: return SampleType::Int32;
      case 64: return SampleType::Int64;
    }
  } else {
    throw Error(ErrorCode::UnsupportedFormat, where,
                "TYPE '" + std::string(type) + "' (expected 'unsigned fixed', 'signed fixed' or 'float')");
  }
  throw Error(ErrorCode::UnsupportedFormat, where,
              "PIXSIZE " + std::to_string(bits) + " bits with TYPE '" + std::string(type) + "'");
}

}  // namespace

ImageReadResult read_inr(ByteStream& stream, std::string_view name, const ImageReadOptions& options) {
  const std::string header = read_header(stream, name);
  // key -> (value, line)
  std::map<std::string, std::pair<std::string, std::uint64_t>, std::less<>> fields;
  std::uint64_t line_no = 0;
  std::size_t pos = 0;
  while (pos < header.size()) {
    const std::size_t eol = header.find('\n', pos);
    const std::string_view line = trim(std::string_view(header).substr(pos, eol - pos));
    pos = eol + 1;
    ++line_no;
    if (line_no == 1 || line.empty() || line.front() == '#') continue;  // magic, padding, comments, end
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos || eq == 0)
      throw Error(ErrorCode::ParseError, at_line(name, line_no),
                  "expected KEY=VALUE, got '" + std::string(line.substr(0, 60)) + "'");
    std::string key(trim(line.substr(0, eq)));
    if (fields.count(key))
      throw Error(ErrorCode::ParseError, at_line(name, line_no), "repeated field " + key);
    fields.emplace(std::move(key), std::make_pair(std::string(trim(line.substr(eq + 1))), line_no));
  }
  auto where_of = [&](std::string_view key) {
    const auto it = fields.find(key);
    return it == fields.end() ? at_line(name, line_no) : at_line(name, it->second.second);
  };
  auto text = [&](std::string_view key) -> const std::string* {
    const auto it = fields.find(key);
    return it == fields.end() ? nullptr : &it->second.first;
  };
  auto dimension = [&](std::string_view key, bool required) -> std::int64_t {
    const std::string* v = text(key);
    if (!v) {
      if (required) throw Error(ErrorCode::ParseError, at_line(name, line_no), "INR header has no " + std::string(key));
      return 1;
    }
    const std::int64_t d = parse_dimension(*v, where_of(key), key);
    if (d <= 0) throw Error(ErrorCode::ParseError, where_of(key), std::string(key) + " must be positive");
    return d;
  };
  auto real = [&](std::string_view key, double fallback) {
    const std::string* v = text(key);
    return v ? parse_real(*v, where_of(key), key) : fallback;
  };

  SampleLayout layout;
  layout.nx = dimension("XDIM", true);
  layout.ny = dimension("YDIM", true);
  layout.nz = dimension("ZDIM", true);
  const std::int64_t vdim = dimension("VDIM", false);
  if (vdim != 1)
    throw Error(ErrorCode::UnsupportedFormat, where_of("VDIM"), "vector images (VDIM " + std::to_string(vdim) + ") are not supported");
  const std::string* type = text("TYPE");
  const std::string* pixsize = text("PIXSIZE");
  if (!type) throw Error(ErrorCode::ParseError, at_line(name, line_no), "INR header has no TYPE");
  if (!pixsize) throw Error(ErrorCode::ParseError, at_line(name, line_no), "INR header has no PIXSIZE");
  std::string_view bits_text = *pixsize;
  if (bits_text.size() > 4 && bits_text.substr(bits_text.size() - 4) == "bits") bits_text.remove_suffix(4);
  const std::int64_t bits = parse_dimension(bits_text, where_of("PIXSIZE"), "PIXSIZE");
  layout.type = sample_type(*type, bits, where_of("TYPE"));
  if (const std::string* cpu = text("CPU")) {
    if (*cpu == "decm" || *cpu == "alpha" || *cpu == "pc") layout.big_endian = false;
    else if (*cpu == "sun" || *cpu == "sgi") layout.big_endian = true;
    else throw Error(ErrorCode::UnsupportedFormat, where_of("CPU"), "CPU '" + *cpu + "' (expected decm, alpha, pc, sun or sgi)");
  }
  if (const std::string* scale = text("SCALE")) {
    if (scale->rfind("2**", 0) != 0) throw Error(ErrorCode::ParseError, where_of("SCALE"), "SCALE must read 2**N, got '" + *scale + "'");
    parse_dimension(std::string_view(*scale).substr(3), where_of("SCALE"), "SCALE exponent");
  }
  ImageReadResult result;
  result.format = ImageFormat::Inr;
  result.image.spacing = {real("VX", 1.0), real("VY", 1.0), real("VZ", 1.0)};
  for (const char* key : {"VX", "VY", "VZ"})
    if (real(key, 1.0) <= 0.0) throw Error(ErrorCode::ParseError, where_of(key), std::string(key) + " must be positive");
  result.image.origin = {real("TX", 0.0), real("TY", 0.0), real("TZ", 0.0)};
  check_image_limits(layout, options, where_of("XDIM"));
  read_samples(stream, layout, header.size(), name, options, result);
  return result;
}

}  // namespace levelset::detail
