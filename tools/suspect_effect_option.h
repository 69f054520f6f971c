// `--suspect-effect-limit` of the commands that adjust a block (adjust, calibrate, flight): one
// option, one meaning (triangulation::AdjustOptions::suspect_effect_limit).
#pragma once

#include <CLI/CLI.hpp>

#include "tools/option_ranges.h"

namespace aerocal::tools {

inline CLI::Option* AddSuspectEffectOption(CLI::App& app, double* limit_sigmas) {
  return app
      .add_option("--suspect-effect-limit",
                  *limit_sigmas,
                  "Failing control surveys that data snooping cannot tell apart are judged by "
                  "their effect: the block re-solved without them; a parameter moving by more "
                  "than this many of its sigmas makes the result not valid (exit 3), else a "
                  "warning names them. (0, 1000], default 1")
      ->check(PositiveUpTo(1e3));
}

}  // namespace aerocal::tools
