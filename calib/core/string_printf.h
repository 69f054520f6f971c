// printf-style formatting into a std::string, for tables and messages (C++17 has no std::format).
#pragma once

#include <string>

namespace aerocal {

/// The text printf would print for `format` and its arguments (any length).
std::string StringPrintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace aerocal
