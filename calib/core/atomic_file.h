// Results are written atomically: to a temporary file beside the target, then renamed over it,
// so a failure never leaves a partial or truncated result (DEVELOPERS brief, STYLE.md section 7).
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace aerocal {

/// Writes `contents` to `path` atomically. Creates missing parent directories. Throws Error on failure.
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Streams into a temporary file and renames it to `path` once `write` returns without throwing.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Reads a whole text file; throws InputError("PATH: cannot read") when it cannot be opened.
std::string ReadTextFile(const std::string& path);

}  // namespace aerocal
