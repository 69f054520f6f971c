// libFuzzer targets of the readers (issue 12): every reader gets arbitrary bytes and must either
// return or throw aerocal::Error (InputError / ConfigError): any other exception, a crash, a hang,
// a leak or undefined behaviour is a finding (ASan/UBSan are on in the fuzz build).
#pragma once

#include "calib/core/error.h"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace aerocal::fuzz {

/// A per-process scratch folder for readers that take paths.
// Removed when the process exits normally (libFuzzer's -max_total_time and -runs end by exit()),
// so that runs do not leave a folder each in the temporary directory; a crash leaves it to look at.
struct ScratchDirectory {
  std::string path;
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

inline const std::string& ScratchDir() {
  static const ScratchDirectory dir = [] {
    const std::string d =
        (std::filesystem::temp_directory_path() / ("aerocal_fuzz_" + std::to_string(::getpid())))
            .string();
    std::filesystem::create_directories(d);
    return ScratchDirectory{d};
  }();
  return dir.path;
}

/// Writes `text` to ScratchDir()/name and returns the path.
inline std::string WriteScratch(const std::string& name, const std::string& text) {
  const std::string path = ScratchDir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  return path;
}

/// Splits the input at "\n%%\n" into up to `n` parts (missing parts are empty).
inline std::vector<std::string> Parts(const uint8_t* data, size_t size, size_t n) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  for (size_t i = 0; i + 1 < n; ++i) {
    const auto at = text.find("\n%%\n");
    if (at == std::string::npos) break;
    parts.push_back(text.substr(0, at + 1));
    text.erase(0, at + 4);
  }
  parts.push_back(text);
  parts.resize(n);
  return parts;
}

}  // namespace aerocal::fuzz

/// Runs `body`; aerocal::Error is the expected answer to bad input, anything else escapes.
#define AEROCAL_FUZZ_EXPECTED_ERRORS(body) \
  try {                                    \
    body;                                  \
  } catch (const ::aerocal::Error&) {      \
  }
