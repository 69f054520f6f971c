// Runs an external program (a Python script, COLMAP) without a shell and waits for it.
#pragma once

#include <string>
#include <vector>

namespace aerocal::tools {

/// Runs argv[0] (searched on PATH) with argv[1...]; its stdout and stderr go to `log_file` when
/// given (created or truncated), else to ours. Returns the exit status; -1 when the program could
/// not be started (not found, not executable) or did not exit normally (a signal).
int RunProgram(const std::vector<std::string>& argv, const std::string& log_file = "");

/// The command line, for messages (arguments joined by spaces, unquoted).
std::string CommandLine(const std::vector<std::string>& argv);

}  // namespace aerocal::tools
