// Shared set-up of the stitching tests: nominal grid cameras, their misplaced truth and simulated
// frames (stitch/layout, stitch/simulation), with fixed seeds.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "stitch/adjustment/frame_measurements.h"
#include "stitch/layout/grid_layout.h"
#include "stitch/simulation/stitch_simulator.h"

namespace aerocal::stitch::testing {

struct SimulatedCamera {
  calib::Camera nominal, truth;
  std::vector<std::string> base;
};

inline SimulatedCamera MakeSimulatedCamera(int rows, int cols, std::vector<std::string> base,
                                           double shear, std::uint64_t seed,
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
inline std::vector<FrameMeasurements> SimulateFrames(const SimulatedCamera& camera, int n,
                                                     int ties, std::uint64_t seed) {
  FrameSimulationOptions options;
  options.ties_per_frame = ties;
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

}  // namespace aerocal::stitch::testing
