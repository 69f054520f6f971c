// Checksums of the input files a result names (FIPS 180-4 SHA-256), so that a report states
// exactly which files a run read and a lab can verify a re-run against them.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal {

/// SHA-256 of `bytes` as 64 lowercase hex digits (FIPS 180-4).
std::string Sha256Hex(const std::string& bytes);

/// The result key `inputs`: [{role, path, bytes, sha256}] of every (role, path) pair, in the order
/// given, each path once (the first role wins); a path that cannot be read throws InputError.
nlohmann::json InputFilesToJson(const std::vector<std::pair<std::string, std::string>>& role_paths);

}  // namespace aerocal
