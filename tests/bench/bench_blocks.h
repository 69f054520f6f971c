// Shared by the benchmarks of block adjustments: wall time, peak RSS and the simulated block of a
// given size (about 4 exposures per strip and strip length, 16 tie points per exposure, 2 surveyed
// points per exposure, one in 20 of them control).
#pragma once

#include "triangulation/simulation/flight_simulator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sys/resource.h>

namespace aerocal::triangulation::bench {

using Clock = std::chrono::steady_clock;

inline double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Peak resident memory of this process, MB.
inline double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

inline SimulatedFlight SimulateBlock(int exposures) {
  FlightSimulationOptions o;
  o.exposures = exposures;
  o.strips = std::max(3, static_cast<int>(std::lround(std::sqrt(exposures / 4.0))));
  o.tie_points = 16 * exposures;
  o.ground_points = std::max(329, 2 * exposures);
  o.control_points = std::max(5, exposures / 20);
  // The per-exposure stitching measurements are not adjusted here; above the simulator's bound
  // (kMaxSimulatedStitchTies, reached at 2,223 exposures) they are left out. The 150 and 600
  // blocks keep theirs, so their random draws and figures stay as measured.
  if (exposures * static_cast<double>(o.stitching.ties_per_frame) > kMaxSimulatedStitchTies)
    o.stitching.ties_per_frame = 0;
  return SimulateFlight(o);
}

}  // namespace aerocal::triangulation::bench
