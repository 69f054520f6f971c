// Error types used at every API boundary (STYLE.md section 7).
//
// InputError: a bad file or value coming from the user, message "FILE:LINE: what (got X, expected
// Y)". ConfigError: a bad option value. LogicError: a violated precondition inside the program
// (AEROCAL_CHECK). Non-convergence and rank defects are never exceptions: they are reported in
// SolveReport.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace aerocal {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InputError : public Error {
 public:
  using Error::Error;
};

class ConfigError : public Error {
 public:
  using Error::Error;
};

class LogicError : public Error {
 public:
  using Error::Error;
};

/// Where a value came from: a file and a 1-based line (0 when unknown).
struct SourceRef {
  std::string file;
  int line = 0;
  std::string ToString() const { return line > 0 ? file + ":" + std::to_string(line) : file; }
};

/// Throws InputError("FILE:LINE: message").
[[noreturn]] inline void ThrowInputError(const SourceRef& where, const std::string& message) {
  throw InputError(where.ToString() + ": " + message);
}

namespace internal {
// Collects a streamed message and throws LogicError when destroyed (used by AEROCAL_CHECK).
class CheckMessage {
 public:
  CheckMessage(const char* file, int line, const char* condition) {
    stream_ << file << ":" << line << ": check failed: " << condition << " ";
  }
  [[noreturn]] ~CheckMessage() noexcept(false) { throw LogicError(stream_.str()); }
  template <typename T>
  CheckMessage& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  std::ostringstream stream_;
};
}  // namespace internal

}  // namespace aerocal

/// AEROCAL_CHECK(cond) << "detail"; throws aerocal::LogicError when cond is false.
#define AEROCAL_CHECK(condition) \
  if (condition) {               \
  } else                         \
    ::aerocal::internal::CheckMessage(__FILE__, __LINE__, #condition)
