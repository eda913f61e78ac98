// read_image: strict readers of 3D scalar images (INRIMAGE-4 and NRRD) into an ImageVolume.
//
// Inputs: a file path, or the bytes of a file plus a name (for messages and the extension).
// Formats, by content (the extension only breaks ties; .gz is looked through):
//   INR   "#INRIMAGE-4#{" text header of KEY=VALUE lines ending with "##}\n" (usually padded to
//         256 bytes; data starts right after "##}\n"), then raw samples. XDIM YDIM ZDIM
//         (required), VDIM (must be 1), TYPE (unsigned fixed | signed fixed | float), PIXSIZE
//         ("8 bits" ... "64 bits"; float: 32 or 64), CPU (decm alpha pc: little endian;
//         sun sgi: big endian), VX VY VZ (spacing, default 1), TX TY TZ (origin, default 0).
//         SCALE is checked for its "2**N" form and otherwise ignored (as CGAL's reader does).
//         The whole file may be gzip-compressed (.inr.gz).
//   NRRD  "NRRD000N" magic (N = 1..5), "field: value" lines until a blank line. type (all
//         NRRD spellings of int8 ... uint64, float, double), dimension (1..3; missing axes get
//         size 1), sizes, encoding (raw | gzip | gz), endian (little | big; required for
//         multi-byte raw/gzip data), spacings or axis-aligned positive "space directions",
//         "space origin", "byte skip" (>= 0, or -1 for raw data at the file's end), "line skip",
//         "data file" (detached data: .nhdr + .raw / .raw.gz, relative to the header's folder;
//         read_image only). Other fields (kinds, units, space, content, key:=value, ...) are
//         ignored.
// Outputs: ImageReadResult; samples as float32, x fastest.
// Errors: levelset::Error, never a crash or an allocation beyond the limits:
//   ParseError        malformed header line, value or field; where = "name:LINE"
//   Truncated         data shorter than the header says; where = "name @ byte N" (N counted
//                     in the decompressed stream for gzip data)
//   LimitExceeded     voxels above max_voxels, samples above max_sample_bytes or (when they
//                     are loaded) above memory_budget, a header longer than 1 MiB, a file
//                     above max_file_bytes
//   NonFinite         NaN/Inf spacing, origin or float sample (Inf samples pass with
//                     allow_infinite); where = line or byte
//   UnsupportedFormat unknown magic, type, encoding, CPU; VDIM > 1; rotated or flipped axes;
//                     detached data from memory
//   Corrupt           broken gzip stream
//   IoError           (read_image only) a file cannot be read
//   Cancelled         the progress hook's token fired
// Samples (options.samples): Load (the default) decodes them into image.samples; Scan decodes
//   and checks them (NonFinite, Truncated, min/max) without keeping them; Skip reads the header
//   only (image.samples stays empty, min/max 0): gzip data are not inflated at all, plain data
//   are only checked to be long enough (Truncated). Skip is what describing a file needs: its
//   cost does not depend on the image's size.
// Cost: one pass, O(voxels) time (Skip: O(header)); memory: the file plus 4 bytes per voxel
//   with Load (gzip data are inflated in 1 MiB pieces straight into the samples, which grow
//   only as data arrives, so a small file claiming a huge image fails with Truncated without
//   allocating it, and a gzip bomb stops at the header's size), the file plus O(1) otherwise.
//   The 4 bytes per voxel are checked against memory_budget before any sample is read.
// Threading: reentrant; no shared state.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/memory_budget.hpp"
#include "core/progress.hpp"
#include "io/image_volume.hpp"

namespace levelset {

enum class ImageFormat { Inr, Nrrd };
std::string_view to_string(ImageFormat format);  // "inr", "nrrd"

enum class ImageSamples { Load, Scan, Skip };

struct ImageReadOptions {
  std::uint64_t max_file_bytes = std::uint64_t{1} << 34;     // compressed / on-disk bytes
  std::uint64_t max_voxels = std::uint64_t{1} << 28;          // 1 GiB of float samples
  std::uint64_t max_sample_bytes = std::uint64_t{1} << 30;   // 4 bytes per voxel in memory
  // Load: the samples (4 bytes per voxel) must fit; core/memory_budget.hpp (--memory-budget).
  std::uint64_t memory_budget = default_memory_budget();
  ImageSamples samples = ImageSamples::Load;
  bool allow_infinite = false;  // +-Inf float samples (cost grids: +Inf = blocked); NaN never
  ProgressHook progress;
};

struct ImageReadResult {
  ImageVolume image;
  ImageFormat format = ImageFormat::Inr;
  std::string sample_type;   // "uint8", "int16", "float", "double", ...
  bool big_endian = false;
  bool gzip = false;         // the data were gzip-compressed
  bool detached = false;     // NRRD data in a separate file
  std::uint64_t file_bytes = 0;  // bytes of the file(s) read
  float min_sample = 0, max_sample = 0;  // Load and Scan only
};

ImageReadResult read_image(const std::filesystem::path& path, const ImageReadOptions& options = {});
ImageReadResult read_image_from_memory(std::string_view bytes, std::string_view name,
                                       const ImageReadOptions& options = {});

}  // namespace levelset
