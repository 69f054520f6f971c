// The in-memory project of a simulated rig flight (rig_flight_simulator.h) with a given rig as its
// camera `rig1`: what `simulate --rig` writes and `ReadProject` reads, without the files' rounding.
#pragma once

#include "triangulation/block/block_io.h"
#include "triangulation/simulation/rig_flight_simulator.h"

namespace aerocal::testing {

inline triangulation::Project RigFlightProject(const triangulation::SimulatedRigFlight& f,
                                               const calib::Rig& rig) {
  triangulation::Project p;
  p.path = "simulated/project.yaml";
  p.rigs["rig1"] = rig;
  p.cameras["rig1"] = rig.heads[rig.ReferenceIndex()].camera;
  p.camera_files["rig1"] = "simulated/rig_nominal.yaml";
  p.exposures = f.exposures_file;
  p.observations = f.observations;
  p.points = f.points_file;
  triangulation::ValidateProject(p);
  return p;
}

}  // namespace aerocal::testing
