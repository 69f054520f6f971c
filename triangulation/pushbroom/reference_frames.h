// The oriented reference frames of cloud control (`aerocal pushbroom control`, issue 17: "matched
// into the oriented reference frame images (their block result from `aerocal adjust`)"): read
// from exposures.csv (FORMATS.md) or straight from the result.json of `aerocal adjust`.
#pragma once

#include "triangulation/block/block.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

/// The adjusted exposures of `aerocal adjust`'s result.json (kind "adjust"; module README
/// "Cloud control"): `exposures[k]` with image, X, Y, Z (m) and omega, phi, kappa (deg) of the
/// adjusted orientation. An exposure the adjustment did not use (`used: false`) has no adjusted
/// orientation and is skipped (counted in `skipped`). Exposure::line is k + 1.
/// InputError (exit 2) with `PATH: exposures[k]: what` on a missing or non-finite value, another
/// kind or schema, `valid: false` (a block result that cannot be trusted is no reference), or no
/// used exposure.
std::vector<Exposure> ReadAdjustedExposures(const std::string& result_path, int* skipped);

}  // namespace aerocal::triangulation
