#include "tools/output_set.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "calib/core/error.h"

namespace aerocal::tools {

namespace fs = std::filesystem;

OutputSet::OutputSet(std::string out_folder) : out_(std::move(out_folder)) {
  std::error_code ec;
  created_out_ = !fs::exists(out_, ec);
  fs::create_directories(out_, ec);
  if (ec) throw InputError(out_ + ": cannot create the output folder: " + ec.message());
  staging_ = (fs::path(out_) / (".aerocal-staging-" + std::to_string(::getpid()))).string();
  fs::remove_all(staging_, ec);
  fs::create_directory(staging_, ec);
  if (ec) throw InputError(out_ + ": cannot write into the output folder: " + ec.message());
}

OutputSet::~OutputSet() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
  if (!committed_ && created_out_ && fs::is_empty(out_, ec)) fs::remove(out_, ec);
}

std::string OutputSet::Staged(const std::string& name) const { return (fs::path(staging_) / name).string(); }

std::string OutputSet::Final(const std::string& name) const { return (fs::path(out_) / name).string(); }

void OutputSet::Commit(const std::vector<std::string>& parts, const std::vector<std::string>& obsolete) {
  std::error_code ec;
  for (const auto& part : parts)
    if (!fs::is_regular_file(Staged(part), ec))
      throw InputError(Final(part) + ": not written (the set of outputs is left as it was)");
  // The previous parts go aside first (into the staging folder), so a failed rename restores them.
  std::vector<std::string> kept, moved;
  auto restore = [&]() {
    std::error_code ignored;
    for (const auto& part : moved) fs::rename(Final(part), Staged(part), ignored);
    for (const auto& part : kept) fs::rename(Staged(part + ".previous"), Final(part), ignored);
  };
  for (const auto& part : parts) {
    if (!fs::exists(Final(part), ec)) continue;
    fs::rename(Final(part), Staged(part + ".previous"), ec);
    if (ec) {
      restore();
      throw InputError(Final(part) + ": cannot replace the file: " + ec.message());
    }
    kept.push_back(part);
  }
  for (const auto& part : parts) {
    fs::rename(Staged(part), Final(part), ec);
    if (ec) {
      restore();
      throw InputError(Final(part) + ": cannot write the file: " + ec.message());
    }
    moved.push_back(part);
  }
  for (const auto& part : obsolete)
    if (std::find(parts.begin(), parts.end(), part) == parts.end()) fs::remove(Final(part), ec);
  committed_ = true;
}

}  // namespace aerocal::tools
