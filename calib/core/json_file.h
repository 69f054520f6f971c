// Reading a JSON document from a file: one place that turns nlohmann's parse error (a byte offset)
// into the `FILE:LINE: what` every reader reports.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal {

/// 1-based line of the byte `offset` in `text` (offsets past the end give the last line).
int LineOfOffset(const std::string& text, size_t offset);

/// Parses `text` (the contents of `path`); InputError("PATH:LINE: invalid JSON (reason)") when it
/// is not a JSON document, and InputError("PATH: a / b: key \"k\" occurs twice in one object")
/// when an object holds a key twice: nlohmann would keep the last, and no reader (ours or another
/// tool's files) may choose silently (issue 37 class 4). The path names the enclosing keys.
nlohmann::json ParseJsonText(const std::string& text, const std::string& path);

/// ReadTextFile (regular-file checks, BOM dropped) + ParseJsonText.
nlohmann::json ReadJsonFile(const std::string& path);

}  // namespace aerocal
