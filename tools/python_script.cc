#include "tools/python_script.h"

#include "tools/run_program.h"

#include <cstdlib>
#include <filesystem>

namespace aerocal::tools {

std::string PythonInterpreter() {
  if (const char* env = std::getenv("AEROCAL_PYTHON"); env && *env) return env;
  if (std::filesystem::exists("/usr/bin/python3")) return "/usr/bin/python3";
  return "python3";
}

bool RunPythonScript(const std::string& script, const std::vector<std::string>& args) {
  std::vector<std::string> argv = {PythonInterpreter(), script};
  argv.insert(argv.end(), args.begin(), args.end());
  return RunProgram(argv) == 0;
}

std::string PythonCommandLine(const std::string& script, const std::vector<std::string>& args) {
  std::vector<std::string> argv = {PythonInterpreter(), script};
  argv.insert(argv.end(), args.begin(), args.end());
  return CommandLine(argv);
}

}  // namespace aerocal::tools
