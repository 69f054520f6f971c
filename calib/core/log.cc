#include "calib/core/log.h"

#include <atomic>
#include <cstdio>

namespace aerocal {
namespace {
std::atomic<int> g_level{static_cast<int>(LogLevel::kWarning)};
}

void SetLogLevel(LogLevel level) { g_level = static_cast<int>(level); }
LogLevel GetLogLevel() { return static_cast<LogLevel>(g_level.load()); }

void LogWarning(const std::string& message) {
  if (g_level >= static_cast<int>(LogLevel::kWarning))
    std::fprintf(stderr, "warning: %s\n", message.c_str());
}

void LogInfo(const std::string& message) {
  if (g_level >= static_cast<int>(LogLevel::kInfo)) std::fprintf(stderr, "%s\n", message.c_str());
}

}  // namespace aerocal
