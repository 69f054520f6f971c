#include "calib/core/atomic_file.h"

#include "calib/core/error.h"

#include <climits>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace aerocal {
namespace {

std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

bool create_missing_folders = true;

// Shared by the output checks: `is_folder` says what the target itself must become; a path the
// user named (`user_path`) may lack its parent folders only when SetCreateMissingFolders allows it.
void CheckOutputPath(const std::string& path,
                     const std::string& what,
                     bool is_folder,
                     bool user_path) {
  const std::string who = what.empty() ? "'" + path + "'" : what + " '" + path + "'";
  if (path.empty())
    throw InputError((what.empty() ? std::string("output path") : what) + ": empty path");
  if (path.size() >= PATH_MAX) throw InputError(who + ": path too long");
  std::stringstream names(path);
  std::string name;
  while (std::getline(names, name, '/'))
    if (name.size() > NAME_MAX)
      throw InputError(who + ": name too long (" + std::to_string(name.size()) + " > " +
                       std::to_string(NAME_MAX) + " characters)");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (is_folder && !S_ISDIR(st.st_mode)) throw InputError(who + ": exists and is not a folder");
    if (!is_folder && !S_ISREG(st.st_mode))
      throw InputError(who + ": exists and is " + KindOf(st.st_mode) + ", not a regular file");
  } else if (errno == ELOOP) {
    throw InputError(who + ": symbolic-link loop");
  } else if (errno == ENOTDIR) {
    throw InputError(who + ": a part of the path is a file, not a folder");
  }
  // The nearest existing ancestor must be a writable folder (missing folders are created).
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (is_folder && ::stat(path.c_str(), &st) == 0) dir = path;
  if (dir.empty()) dir = ".";
  std::filesystem::path first_missing;
  while (::stat(dir.c_str(), &st) != 0) {
    first_missing = dir;
    if (errno == ENOTDIR) throw InputError(who + ": a part of the path is a file, not a folder");
    if (errno == ELOOP) throw InputError(who + ": symbolic-link loop");
    if (!dir.has_parent_path() || dir.parent_path() == dir) break;
    dir = dir.parent_path();
  }
  if (::stat(dir.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode))
      throw InputError(who + ": '" + dir.string() + "' is a file, not a folder");
    if (::access(dir.c_str(), W_OK) != 0)
      throw InputError(who + ": folder '" + dir.string() + "' is not writable");
  }
  if (user_path && !create_missing_folders && !first_missing.empty())
    throw InputError(who + ": folder '" + first_missing.string() +
                     "' does not exist (create it, or give --mkdir to have it created)");
}

}  // namespace

void SetCreateMissingFolders(bool create) { create_missing_folders = create; }

void CheckOutputFile(const std::string& path, const std::string& what) {
  CheckOutputPath(path, what, false, true);
}

void CheckOutputFolder(const std::string& path, const std::string& what) {
  CheckOutputPath(path, what, true, true);
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  CheckOutputPath(path, "", false, false);  // the program's own sub-folders are created
  const fs::path target(path);
  if (target.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec) throw InputError(path + ": cannot create the output folder: " + ec.message());
  }
  std::string temp = path + ".tmp" + std::to_string(::getpid());
  if (fs::path(temp).filename().string().size() > NAME_MAX)  // keep the temporary name legal
    temp = (target.parent_path() / (".aerocal.tmp" + std::to_string(::getpid()))).string();
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    // An output path the user cannot write to is a bad input (exit 2), not an internal error.
    if (!out) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
    try {
      write(out);
    } catch (...) {
      out.close();
      std::remove(temp.c_str());
      throw;
    }
    out.flush();
    if (!out) {
      std::remove(temp.c_str());
      throw InputError(path + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(temp, target, ec);
  if (ec) {
    std::remove(temp.c_str());
    throw InputError(path + ": cannot replace the file: " + ec.message());
  }
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << contents; });
}

void CheckInputFile(const std::string& path) {
  if (path.empty()) throw InputError("input file: empty path");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ELOOP) throw InputError(path + ": symbolic-link loop");
    if (err == ENOENT) throw InputError(path + ": no such file");
    if (err == ENOTDIR) throw InputError(path + ": a part of the path is a file, not a folder");
    if (err == ENAMETOOLONG) throw InputError(path + ": name too long");
    throw InputError(path + ": cannot read (" + std::strerror(err) + ")");
  }
  if (!S_ISREG(st.st_mode))
    throw InputError(path + ": is " + KindOf(st.st_mode) + ", not a regular file");
  if (::access(path.c_str(), R_OK) != 0)
    throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
}

std::string ReadTextFile(const std::string& path) {
  CheckInputFile(path);
  // O_NONBLOCK: should the path have become a FIFO since the check, the open does not block.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw InputError(path + ": cannot read (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw InputError(path + ": not a regular file");
  }
  std::string text;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw InputError(path + ": cannot read (" + std::strerror(err) + ")");
    }
    if (n == 0) break;
    text.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);  // UTF-8 byte-order mark
  return text;
}

}  // namespace aerocal
