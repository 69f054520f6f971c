// The documented range of a numeric option, enforced while parsing (issue 37): CLI11's Range and
// PositiveNumber let NaN through (every comparison with NaN is false), so every numeric option
// takes one of these instead. The range shows in --help ("in [lo, hi]") and is read by the test
// that walks every option of every command (tests/tools/bad_input2_test.cc, `aerocal options`).
#pragma once

#include "calib/core/csv.h"  // FormatNumber

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <string>

namespace aerocal::tools {

/// A finite number within [lo, hi], or within (lo, hi] when `open_lo` (a value that must be > lo).
/// Refuses NaN, infinities, text that is not a number and values outside; the message names the
/// range and the value (CLI11 adds the option's name): exit 2.
inline CLI::Validator FiniteRange(double lo, double hi, bool open_lo = false) {
  const std::string range =
      std::string(open_lo ? "(" : "[") + FormatNumber(lo) + ", " + FormatNumber(hi) + "]";
  return CLI::Validator(
      [lo, hi, open_lo, range](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end == text.c_str() || *end != '\0')
          return "must be a number in " + range + " (got '" + text + "')";
        if (!std::isfinite(value))
          return "must be a finite number in " + range + " (got '" + text + "')";
        if (value > hi || value < lo || (open_lo && !(value > lo)))
          return "must be in " + range + " (got " + text + ")";
        return "";
      },
      "in " + range);
}

/// A finite number > 0 and <= hi.
inline CLI::Validator PositiveUpTo(double hi) { return FiniteRange(0, hi, true); }

}  // namespace aerocal::tools
