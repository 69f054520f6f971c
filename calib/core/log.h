// Diagnostics shim: the only place that decides where warnings go, so no glog/absl header leaks
// into the API. Library code never logs results; results are returned as data.
#pragma once

#include <string>

namespace aerocal {

enum class LogLevel { kQuiet = 0, kWarning = 1, kInfo = 2 };

void SetLogLevel(LogLevel level);
LogLevel GetLogLevel();
void LogWarning(const std::string& message);
void LogInfo(const std::string& message);

}  // namespace aerocal
