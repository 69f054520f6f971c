// Shared set-up of the stitching tests: nominal grid cameras, their misplaced truth and simulated
// frames (stitch/layout, stitch/simulation), with fixed seeds.
#pragma once

#include "stitch/adjustment/frame_measurements.h"
#include "stitch/layout/grid_layout.h"
#include "stitch/simulation/stitch_simulator.h"

#include <random>
#include <string>
#include <vector>

namespace aerocal::stitch::testing {

struct SimulatedCamera {
  calib::Camera nominal, truth;
  std::vector<std::string> base;
};

inline SimulatedCamera MakeSimulatedCamera(
    int rows,
    int cols,
    std::vector<std::string> base,
    double shear,
    std::uint64_t seed,
    calib::MappingModel nominal_model = calib::MappingModel::kAffine) {
  GridLayoutOptions layout;
  layout.rows = rows;
  layout.cols = cols;
  layout.base_ids = base;
  layout.model = nominal_model;
  SimulatedCamera out;
  out.base = base;
  out.nominal = MakeGridCamera(layout);
  MisplacementOptions misplacement;
  misplacement.shear = shear;
  std::mt19937_64 rng(seed);
  out.truth = MakeMisplacedCamera(out.nominal, base, misplacement, rng);
  return out;
}

/// `n` frames "0001", "0002", ... of `truth`, grouped against the nominal camera.
/// `noise_scale` multiplies the simulator's default noise (0.1 px ties, 0.05 px references);
/// 0 gives noise-free frames (their v^T P v is the non-centrality of a model that misses the
/// truth).
inline std::vector<FrameMeasurements> SimulateFrames(
    const SimulatedCamera& camera, int n, int ties, std::uint64_t seed, double noise_scale = 1.0) {
  FrameSimulationOptions options;
  options.ties_per_frame = ties;
  options.noise_px *= noise_scale;
  options.reference_noise_px *= noise_scale;
  std::mt19937_64 rng(seed);
  std::vector<StitchObservation> rows;
  for (int i = 1; i <= n; ++i) {
    char frame[16];
    std::snprintf(frame, sizeof(frame), "%04d", i);
    const auto frame_rows = SimulateFrame(camera.truth, frame, options, rng);
    rows.insert(rows.end(), frame_rows.begin(), frame_rows.end());
  }
  return GroupByFrame(camera.nominal, rows, "simulated");
}

/// Leaves only the first `keep` ties of `frame` that touch sub-image `id` (others untouched).
inline void KeepTiesTouching(const calib::Camera& camera,
                             const std::string& id,
                             int keep,
                             FrameMeasurements* frame) {
  const int sub = camera.SubimageIndex(id);
  std::vector<TieMeasurement> kept;
  int touching = 0;
  for (const auto& tie : frame->ties) {
    bool on = false;
    for (const auto& ray : tie.rays) on = on || ray.subimage == sub;
    if (on && ++touching > keep) continue;
    kept.push_back(tie);
  }
  frame->ties = kept;
}

}  // namespace aerocal::stitch::testing
