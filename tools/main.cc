// The aerocal command line: argument parsing and dispatch only; no algorithms live here.
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/log.h"
#include "tools/command_registry.h"
#include "tools/deprecated_options.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>

namespace aerocal::tools {
std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}
namespace {

// CLI11 converts "nan", "inf" and "1e999" into a double that passes its range checks; no option of
// aerocal takes a non-finite value, so every floating-point option is checked once here.
void RejectNonFiniteOptions(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.find("FLOAT") == std::string::npos && type.find("NUMBER") == std::string::npos)
      continue;
    for (const std::string& text : option->results()) {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end != text.c_str() && !std::isfinite(value))
        throw aerocal::ConfigError(option->get_name() + ": must be a finite number (got '" + text +
                                   "')");
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) RejectNonFiniteOptions(*sub);
}

}  // namespace
}  // namespace aerocal::tools

int main(int argc, char** argv) {
  using namespace aerocal::tools;
  CLI::App app{
      "aerocal: calibration of large-format and multi-head aerial cameras.\n"
      "Sub-image stitching, self-calibrating aerial triangulation with the 10-parameter model,\n"
      "control/check-point statistics and calibration reports."};
  app.set_version_flag("--version", std::string("aerocal ") + AEROCAL_VERSION);
  app.require_subcommand(1);
  bool quiet = false, verbose = false, mkdir = false;
  app.add_flag("--quiet", quiet, "Print no warnings");
  app.add_flag("--verbose", verbose, "Print solver progress and extra information");
  app.add_flag("--mkdir", mkdir, "Create missing parent folders of output paths (else an error)");
  std::map<CLI::App*, CommandRun> runs;
  std::vector<std::pair<CLI::App*, const CommandEntry*>> subs;
  for (const auto& entry : CommandRegistry()) {
    CLI::App* sub = app.add_subcommand(entry.name, entry.description);
    sub->option_defaults()->always_capture_default();  // --help shows every default
    sub->fallthrough();  // the global --verbose / --quiet also after the command's name
    subs.emplace_back(sub, &entry);
  }
  std::vector<std::string> args(argv, argv + argc);
  const std::vector<std::string> deprecations = RewriteDeprecatedOptions(args);
  std::vector<char*> rewritten;
  for (std::string& arg : args) rewritten.push_back(arg.data());
  try {
    for (auto& [sub, entry] : subs) runs[sub] = entry->setup(*sub);
    app.parse(static_cast<int>(rewritten.size()), rewritten.data());
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }
  if (quiet) aerocal::SetLogLevel(aerocal::LogLevel::kQuiet);
  if (verbose) aerocal::SetLogLevel(aerocal::LogLevel::kInfo);
  aerocal::SetCreateMissingFolders(mkdir);
  for (const std::string& warning : deprecations) aerocal::LogWarning(warning);
  try {
    RejectNonFiniteOptions(app);
    for (auto& [sub, run] : runs)
      if (sub->parsed()) return run();
  } catch (const aerocal::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const aerocal::ConfigError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const YAML::Exception& e) {  // a user's YAML the readers did not catch
    std::fprintf(stderr, "error: YAML input: %s\n", e.what());
    return kExitBadInput;
  } catch (const nlohmann::json::exception& e) {  // a user's JSON (stitch result) malformed
    std::fprintf(stderr, "error: JSON input: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {  // a user's path
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitInternal;
}
