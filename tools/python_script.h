// The report, certificate and plot scripts (matplotlib) run by one interpreter chosen in one place.
#pragma once

#include <string>
#include <vector>

namespace aerocal::tools {

/// $AEROCAL_PYTHON when set, else Debian's /usr/bin/python3 (where setup.sh installs matplotlib;
/// a python3 earlier on PATH, e.g. pyenv's, often lacks it), else python3 from PATH.
std::string PythonInterpreter();

/// Runs PythonInterpreter() SCRIPT ARGS... without a shell; true when it exits with 0.
bool RunPythonScript(const std::string& script, const std::vector<std::string>& args);

/// The command line RunPythonScript runs, for messages.
std::string PythonCommandLine(const std::string& script, const std::vector<std::string>& args);

}  // namespace aerocal::tools
