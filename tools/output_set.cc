#include "tools/output_set.h"

#include "calib/core/error.h"

#include <algorithm>
#include <filesystem>
#include <system_error>
#include <unistd.h>

namespace aerocal::tools {

namespace fs = std::filesystem;

namespace {

// A folder's key: absolute and normal, so "out" and "./out" are one folder.
std::string FolderKey(const std::string& folder) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(folder.empty() ? "." : folder, ec);
  return (ec ? fs::path(folder) : absolute).lexically_normal().string();
}

}  // namespace

OutputSet::OutputSet(std::string out_folder) : out_(std::move(out_folder)) {
  staging_ = StagingOf(out_);
}

const std::string& OutputSet::StagingOf(const std::string& named) {
  const std::string folder = named.empty() ? "." : named;
  const std::string key = FolderKey(folder);
  const auto known = staging_of_.find(key);
  if (known != staging_of_.end()) return known->second;
  std::error_code ec;
  if (!fs::exists(folder, ec)) {
    fs::create_directories(folder, ec);
    if (ec) throw InputError(folder + ": cannot create the output folder: " + ec.message());
    created_.push_back(folder);
  }
  const std::string staging =
      (fs::path(folder) / (".aerocal-staging-" + std::to_string(::getpid()))).string();
  fs::remove_all(staging, ec);
  fs::create_directory(staging, ec);
  if (ec) throw InputError(folder + ": cannot write into the output folder: " + ec.message());
  return staging_of_[key] = staging;
}

OutputSet::~OutputSet() {
  std::error_code ec;
  for (const auto& [folder, staging] : staging_of_) fs::remove_all(staging, ec);
  if (committed_) return;
  for (auto it = created_.rbegin(); it != created_.rend(); ++it)
    if (fs::is_empty(*it, ec)) fs::remove(*it, ec);
}

std::string OutputSet::Staged(const std::string& name) const {
  return (fs::path(staging_) / name).string();
}

std::string OutputSet::Final(const std::string& name) const {
  return (fs::path(out_) / name).string();
}

std::string OutputSet::StagePath(const std::string& final_path) {
  const fs::path path(final_path);
  const std::string key = FolderKey(final_path);
  for (const auto& staged : elsewhere_)
    if (FolderKey(staged) == key) throw LogicError(final_path + ": staged twice in one output set");
  elsewhere_.push_back(final_path);
  return (fs::path(StagingOf(path.parent_path().string())) / path.filename()).string();
}

void OutputSet::Commit(const std::vector<std::string>& parts,
                       const std::vector<std::string>& obsolete) {
  // (staged, final) of every part.
  std::vector<std::pair<std::string, std::string>> moves;
  for (const auto& part : parts) moves.emplace_back(Staged(part), Final(part));
  for (const auto& path : elsewhere_)
    moves.emplace_back(
        (fs::path(StagingOf(fs::path(path).parent_path().string())) / fs::path(path).filename())
            .string(),
        path);
  std::error_code ec;
  for (const auto& [staged, final_path] : moves)
    if (!fs::exists(staged, ec))
      throw InputError(final_path + ": not written (the set of outputs is left as it was)");
  // The previous parts go aside first (beside their staged successors), so a failed rename
  // restores them.
  std::vector<size_t> kept, moved;
  auto restore = [&]() {
    std::error_code ignored;
    for (size_t i : moved) fs::rename(moves[i].second, moves[i].first, ignored);
    for (size_t i : kept) fs::rename(moves[i].first + ".previous", moves[i].second, ignored);
  };
  for (size_t i = 0; i < moves.size(); ++i) {
    if (!fs::exists(fs::symlink_status(moves[i].second, ec))) continue;
    fs::rename(moves[i].second, moves[i].first + ".previous", ec);
    if (ec) {
      restore();
      throw InputError(moves[i].second + ": cannot replace it: " + ec.message());
    }
    kept.push_back(i);
  }
  for (size_t i = 0; i < moves.size(); ++i) {
    fs::rename(moves[i].first, moves[i].second, ec);
    if (ec) {
      restore();
      throw InputError(moves[i].second + ": cannot write it: " + ec.message());
    }
    moved.push_back(i);
  }
  for (const auto& part : obsolete)
    if (std::find(parts.begin(), parts.end(), part) == parts.end()) fs::remove_all(Final(part), ec);
  committed_ = true;
}

void CheckDistinctPath(const std::string& path,
                       const std::string& option,
                       const std::string& other,
                       const std::string& other_name) {
  if (path.empty() || other.empty()) return;
  std::error_code ec, ec_other;
  bool same =
      fs::weakly_canonical(path, ec) == fs::weakly_canonical(other, ec_other) && !ec && !ec_other;
  if (!same && fs::exists(path, ec) && fs::exists(other, ec))
    same = fs::equivalent(path, other, ec) && !ec;
  if (same)
    throw ConfigError(option + ": '" + path + "' is " + other_name + " ('" + other +
                      "'): a command never writes over its own input or another of its outputs");
}

}  // namespace aerocal::tools
