#include "core/file_extension.hpp"

#include <sys/stat.h>

#include <cctype>

#include "core/error.hpp"
#include "core/file_io.hpp"

namespace levelset {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void require_extension(const std::filesystem::path& path,
                       std::span<const std::string_view> allowed, std::string_view what) {
  // A device, FIFO or socket (or /dev/stdout, a link to one) has no extension to check; whether
  // it may be written at all is core/file_io.hpp's decision (allow_special_outputs).
  struct stat st{};
  if (::stat(path.c_str(), &st) == 0 &&
      (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode) || is_stdout(path)))
    return;
  const std::string ext = lower_extension(path);
  std::string list;
  for (std::string_view a : allowed) {
    if (a == ext) return;
    list += (list.empty() ? "" : ", ") + std::string(a);
  }
  throw Error(ErrorCode::UnsupportedFormat, path.string(),
              "expected a file name for " + std::string(what) + " (" + list + "), found " +
                  (ext.empty() ? std::string("no extension") : "the extension '" + ext + "'"));
}

}  // namespace levelset
