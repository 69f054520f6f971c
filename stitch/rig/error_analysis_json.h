// The result of `aerocal rig error-analysis` (kind "rig_error_analysis"): the document, the
// histogram and bound-map CSV texts, and the grid of targets. Keys (stitch/README.md
// "Multi-head rigs"): per_source [{source, plus_px, minus_px}], linear {sigma_px, bound_px, share},
// monte_carlo {n, seed, sigma_px, mean_px, bound_px, bound_radial_px, max_abs_px} as issue 13
// fixes them, plus target, sources, worst_case, relief and (with a grid) grid.
#pragma once

#include "calib/camera/rig.h"
#include "stitch/rig/error_analysis.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::stitch {

/// Targets of an N x N grid of virtual pixels (cell centres over the virtual format), each in
/// every non-reference head whose format holds it, analysed as AnalyseTarget does; the Monte-Carlo
/// of grid point i uses seed + i. Grid points no non-reference head sees are listed in `unseen`.
struct GridAnalysis {
  int n = 0;
  std::vector<TargetAnalysis> points;
  std::vector<Eigen::Vector2d> unseen;
  /// Index in `points` of the largest linear radial bound (-1 when empty).
  int worst = -1;
};
GridAnalysis AnalyseGrid(const calib::Rig& rig,
                         double height_m,
                         const ErrorLimits& limits,
                         int n,
                         int samples,
                         std::uint64_t seed);

struct ErrorAnalysisFiles {
  std::string histogram_csv, histogram_png;  // names beside the result (empty: none)
  std::string bound_map_csv, bound_map_png;
};

/// The result document for one analysed target (or a grid's worst point plus the grid).
nlohmann::json ErrorAnalysisToJson(const calib::Rig& rig,
                                   double height_m,
                                   const ErrorLimits& limits,
                                   const TargetAnalysis& target,
                                   const GridAnalysis* grid,
                                   double relief_m,
                                   const ErrorAnalysisFiles& files);

/// `quantity,bin_low_px,bin_high_px,count` rows for ex, ey (bins over [-max, max]) and the radial
/// error (over [0, max]).
std::string HistogramCsv(const MonteCarloResult& monte_carlo, int bins);

/// One row per analysed grid target: virtual pixel, head, head pixel, linear sigmas and radial
/// bound, the maximum-error radial worst case, the Monte-Carlo radial bound.
std::string BoundMapCsv(const calib::Rig& rig, const GridAnalysis& grid);

}  // namespace aerocal::stitch
