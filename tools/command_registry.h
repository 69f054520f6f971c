// Commands of the `aerocal` executable. Each command lives in tools/cmd_<name>.cc and registers
// itself with a static AEROCAL_REGISTER_COMMAND, so adding a command edits no other file.
//
// A command adds its CLI11 sub-app (options with help texts) in `setup` and returns a callback
// that runs it and returns the exit code (STYLE.md section 7): 0 converged / done, 2 bad input
// (nothing written), 3 ran but did not converge or is not determinable, 1 internal error.
// Throwing aerocal::InputError / ConfigError gives exit 2 with "error: FILE:LINE: ..." on stderr.
#pragma once

#include "tools/exit_codes.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace aerocal::tools {

/// Check of a random seed option: decimal digits only, within 0 .. 2^64 - 1 (CLI11 itself turns
/// "-1" into 2^64 - 1 and accepts a value past 2^64).
inline CLI::Validator SeedCheck() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        errno = 0;
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
            (std::strtoull(text.c_str(), nullptr, 10), errno == ERANGE))
          return "must be an integer within 0 .. 18446744073709551615 (got '" + text + "')";
        return "";
      },
      "UINT64");
}

using CommandRun = std::function<int()>;
using CommandSetup = std::function<CommandRun(CLI::App& app)>;

struct CommandEntry {
  std::string name, description;
  CommandSetup setup;
};

std::vector<CommandEntry>& CommandRegistry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, std::string description, CommandSetup setup) {
    CommandRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace aerocal::tools

#define AEROCAL_REGISTER_COMMAND(ident, name, description, setup) \
  static ::aerocal::tools::CommandRegistrar ident##_registrar(name, description, setup)
