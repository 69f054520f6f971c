#include "stitch/image_io/image_codecs.h"

#include "calib/core/error.h"
#include "stitch/image_io/image_codecs_table.h"

#include <cstdlib>
#include <dlfcn.h>
#include <filesystem>
#include <string>
#include <vector>

namespace aerocal::stitch {
namespace {

/// The module's path in the folder that holds `file`.
std::string BesideFile(const std::filesystem::path& file) {
  return (file.parent_path() / kImageCodecsFile).string();
}

/// The places image_codecs.h lists, in its order (duplicates are harmless: tried twice).
std::vector<std::string> Candidates() {
  std::vector<std::string> places;
  if (const char* env = std::getenv("AEROCAL_IMAGE_CODECS"); env && *env) places.emplace_back(env);
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&DecodeImageFile), &info) && info.dli_fname &&
      info.dli_fname[0] == '/')
    places.push_back(BesideFile(info.dli_fname));
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::canonical("/proc/self/exe", error);
  if (!error) places.push_back(BesideFile(exe));
#ifdef AEROCAL_IMAGE_CODECS_BUILD_PATH
  places.emplace_back(AEROCAL_IMAGE_CODECS_BUILD_PATH);
#endif
  return places;
}

const ImageCodecsTable& LoadTable() {
  std::string tried;
  for (const std::string& place : Candidates()) {
    void* module = dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);  // never closed: used to the end
    if (!module) {
      tried += "\n  " + place + ": " + dlerror();
      continue;
    }
    using Entry = const ImageCodecsTable* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(module, kImageCodecsSymbol));
    const ImageCodecsTable* table = entry ? entry() : nullptr;
    if (table && table->abi == kImageCodecsAbi) return *table;
    tried += "\n  " + place + ": not a module of this aerocal (stale build or install?)";
  }
  throw Error(std::string("cannot load OpenCV's image codecs (") + kImageCodecsFile +
              "; set AEROCAL_IMAGE_CODECS to its path). Tried:" + tried);
}

const ImageCodecsTable& Table() {
  static const ImageCodecsTable& table = LoadTable();  // thread-safe once; retried if it threw
  return table;
}

}  // namespace

cv::Mat DecodeImageFile(const std::string& path, int flags) { return Table().read(path, flags); }

bool EncodeImageFile(const std::string& path, const cv::Mat& image) {
  return Table().write(path, image);
}

}  // namespace aerocal::stitch
