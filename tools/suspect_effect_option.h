// `--suspect-effect-limit` of the commands that snoop (adjust, calibrate, flight, rig stitch): one
// option, one meaning (calib/problem/suspect_effect.h).
#pragma once

#include "tools/option_ranges.h"

#include <CLI/CLI.hpp>

namespace aerocal::tools {

inline CLI::Option* AddSuspectEffectOption(CLI::App& app, double* limit_sigmas) {
  return app
      .add_option("--suspect-effect-limit",
                  *limit_sigmas,
                  "Suspects that data snooping cannot resolve (failing control surveys it cannot "
                  "tell apart; rig stitch: failing ties kept for their standard position) are "
                  "judged by their effect: the problem re-solved without them; a calibrated "
                  "parameter moving by more than this many of its sigmas makes the result not "
                  "valid (exit 3), else a warning names them. (0, 1000], default 1")
      ->check(PositiveUpTo(1e3));
}

}  // namespace aerocal::tools
