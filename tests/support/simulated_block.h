// The simulated example flight as an in-memory block (the nominal camera, approximate exposures,
// virtual-image observations and the surveyed points with their roles), for the adjustment tests.
#pragma once

#include "triangulation/block/block.h"
#include "triangulation/simulation/flight_simulator.h"

namespace aerocal::testing {

inline triangulation::Project ProjectFromFlight(const triangulation::SimulatedFlight& f) {
  triangulation::Project p;
  p.path = "simulated";
  p.cameras["cam1"] = f.nominal;
  p.exposures = f.exposures_file;
  p.observations = f.observations;
  p.points = f.points_file;
  p.frame.description = "simulated local frame";
  return p;
}

}  // namespace aerocal::testing
