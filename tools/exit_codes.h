// The exit codes of `aerocal` (docs/style.md "Errors and exit codes"): 0 converged / done, 1
// internal error, 2 bad input (nothing written), 3 ran but did not converge or is not valid. A
// header of their own, so that callers without the command line (the Python module) name them too.
#pragma once

namespace aerocal::tools {

inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitNotConverged = 3;

}  // namespace aerocal::tools
