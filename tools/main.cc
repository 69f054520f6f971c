// The aerocal command line: argument parsing and dispatch only; no algorithms live here.
#include <cstdio>
#include <exception>
#include <map>

#include <CLI/CLI.hpp>

#include "calib/core/error.h"
#include "calib/core/log.h"
#include "tools/command_registry.h"

namespace aerocal::tools {
std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}
}  // namespace aerocal::tools

int main(int argc, char** argv) {
  using namespace aerocal::tools;
  CLI::App app{
      "aerocal: calibration of large-format and multi-head aerial cameras.\n"
      "Sub-image stitching, self-calibrating aerial triangulation with the 10-parameter model,\n"
      "control/check-point statistics and calibration reports."};
  app.set_version_flag("--version", std::string("aerocal ") + AEROCAL_VERSION);
  app.require_subcommand(1);
  bool quiet = false, verbose = false;
  app.add_flag("--quiet", quiet, "Print no warnings");
  app.add_flag("--verbose", verbose, "Print solver progress and extra information");
  std::map<CLI::App*, CommandRun> runs;
  std::vector<std::pair<CLI::App*, const CommandEntry*>> subs;
  for (const auto& entry : CommandRegistry()) {
    CLI::App* sub = app.add_subcommand(entry.name, entry.description);
    sub->option_defaults()->always_capture_default();  // --help shows every default
    subs.emplace_back(sub, &entry);
  }
  try {
    for (auto& [sub, entry] : subs) runs[sub] = entry->setup(*sub);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }
  if (quiet) aerocal::SetLogLevel(aerocal::LogLevel::kQuiet);
  if (verbose) aerocal::SetLogLevel(aerocal::LogLevel::kInfo);
  try {
    for (auto& [sub, run] : runs)
      if (sub->parsed()) return run();
  } catch (const aerocal::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const aerocal::ConfigError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitInternal;
}
