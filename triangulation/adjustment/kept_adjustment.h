// The solved problem of an adjustment, kept after Adjust() returns, and the covariance of entries
// named after the run (Python's AdjustmentResult.covariance, issue 32).
//
// The run's covariance (BlockAdjustment::Run) holds the interior with everything and each exterior
// orientation with itself only: enough for the result's sigmas and correlations, not for the cross
// blocks a user asks for later (exposure x exposure, point x exposure). Rather than compute every
// pair at solve time (quadratic in the block size), the final BlockAdjustment and the project it
// refers to are kept, and CovarianceOfNamed asks its builder for exactly the requested blocks and
// all their pairs: ProblemBuilder::EstimateCovariance at the solution, the same math and the same
// scaling sigma0^2 as the run's own covariance (pairs outside the selected inverse's pattern are
// solved against the factor there, never left 0).
#pragma once

#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// The final adjustment of a run and the project it was built from (it refers to it: both on the
/// heap, so moving this struct keeps the reference valid). Empty when nothing was kept.
struct KeptAdjustment {
  std::unique_ptr<const Project> project;
  std::unique_ptr<BlockAdjustment> adjustment;
};

/// sigma0^2 Q of named entries, rows and columns in the order of `names` expanded:
/// - "camera ID" (every interior parameter, the model's order) or "camera ID.NAME" (one), in the
///   parameter table's units;
/// - "exposure ID": X, Y, Z (m) and omega, phi, kappa (deg, CONVENTIONS.md section 4) of the
///   projection centre and attitude, in the ADJUSTMENT frame (the frame of the result's sigmas:
///   the local tangent plane for local / crs frames, the UTM zone for utm, as given otherwise);
/// - "point ID": X, Y, Z (m) of an adjusted ground point, in the adjustment frame.
struct NamedCovariance {
  std::vector<std::string> names;  // "camera cam1.c", "exposure 0012.X", "point T17.Z", ...
  Eigen::MatrixXd matrix;          // symmetric; fixed entries have zero rows
};

/// The joint covariance of the named entries from the kept adjustment of `result` (see above).
/// ConfigError naming the entry for a name the result does not hold (an unknown camera,
/// parameter, exposure or point; an exposure or point the adjustment left out), and when the
/// covariance cannot be computed (singular normal matrix: the builder's message).
NamedCovariance CovarianceOfNamed(BlockAdjustment& adjustment,
                                  const AdjustmentResult& result,
                                  const std::vector<std::string>& names);

}  // namespace aerocal::triangulation
