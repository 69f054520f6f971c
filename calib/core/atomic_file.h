// Results are written atomically: to a temporary file beside the target, then renamed over it,
// so a failure never leaves a partial or truncated result (DEVELOPERS brief, STYLE.md section 7).
// Inputs are checked before they are opened: only regular files are read (a FIFO would block, a
// device never end, a directory is no file), and outputs only ever replace regular files.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace aerocal {

/// Writes `contents` to `path` atomically. Creates missing parent directories. Throws InputError
/// when `path` is not a usable output file path (see CheckOutputFile), Error on other failures.
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Streams into a temporary file and renames it to `path` once `write` returns without throwing.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Throws InputError("PATH: what") unless `path` names an existing regular file the process may
/// read (following symbolic links): a missing path, a directory, a FIFO, a device or socket, a
/// symbolic-link loop and an unreadable file are refused BEFORE anything is opened.
void CheckInputFile(const std::string& path);

/// Reads a whole regular text file (CheckInputFile first); a leading UTF-8 byte-order mark is
/// dropped. Throws InputError("PATH: ...") when it cannot be read.
std::string ReadTextFile(const std::string& path);

/// Throws InputError("WHAT: ...") unless `path` can become a regular output file: not empty, not an
/// existing directory, device, FIFO or socket, every name within NAME_MAX and the whole within
/// PATH_MAX, no existing ancestor that is not a folder, a writable nearest existing folder, and
/// (see SetCreateMissingFolders) an existing parent folder.
/// `what` names the option (e.g. "--out") or is empty to name the path itself. Nothing is created.
void CheckOutputFile(const std::string& path, const std::string& what = "");

/// As CheckOutputFile, for an output folder (created later): an existing path must be a folder.
void CheckOutputFolder(const std::string& path, const std::string& what = "");

/// Whether CheckOutputFile / CheckOutputFolder accept a path whose parent folders do not exist yet
/// (they are created when written). The library's default is yes; the command line says no unless
/// `--mkdir` is given (issue 33 item 5: a mistyped folder is an error, not a new folder tree). An
/// output folder itself (CheckOutputFolder) is always created; only its parents must exist.
void SetCreateMissingFolders(bool create);

}  // namespace aerocal
