#include "tools/python_script.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

extern char** environ;

namespace aerocal::tools {

std::string PythonInterpreter() {
  if (const char* env = std::getenv("AEROCAL_PYTHON"); env && *env) return env;
  if (std::filesystem::exists("/usr/bin/python3")) return "/usr/bin/python3";
  return "python3";
}

bool RunPythonScript(const std::string& script, const std::vector<std::string>& args) {
  std::vector<std::string> argv_strings = {PythonInterpreter(), script};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, argv_strings[0].c_str(), nullptr, nullptr, argv.data(), environ) != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

std::string PythonCommandLine(const std::string& script, const std::vector<std::string>& args) {
  std::string line = PythonInterpreter() + " " + script;
  for (const auto& a : args) line += " " + a;
  return line;
}

}  // namespace aerocal::tools
