// A simulated line of the four-head uav4 rig (triangulation/simulation/rig_flight_simulator.h) as
// the inputs of the self-calibrating stitching (stitch/rig/self_calibration.h), and the noise
// floor of its stitching RMS metric: shared by the library test, the sigma-vs-spread study and the
// benchmark.
#pragma once

#include "stitch/rig/rig_conversion.h"
#include "stitch/rig/rig_design.h"
#include "stitch/rig/self_calibration.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace aerocal::stitch::testing {

struct RigStitchInputs {
  std::vector<RigStitchExposure> exposures;
  std::vector<RigStitchTie> ties;
  std::vector<RigStitchObservation> observations;
  std::vector<StandardPosition> positions;
};

inline const std::vector<StandardPosition>& Uav4Positions() {
  static const std::vector<StandardPosition> positions =
      DesignRig(triangulation::MakeNominalRig(triangulation::RigPreset::kUav4), 300.0, 200)
          .standard_positions;
  return positions;
}

/// The default uav4 line (`simulate --rig uav4`) with `exposures` exposures and `seed`.
inline triangulation::RigFlightSimulationOptions Uav4Line(std::uint64_t seed, int exposures) {
  triangulation::RigFlightSimulationOptions o =
      triangulation::RigFlightSimulationOptions::DefaultUav4();
  o.flight.seed = seed;
  o.flight.exposures = exposures;
  for (const auto& s : Uav4Positions())
    o.stitch_ties.standard_positions.push_back({s.name, s.virtual_px});
  return o;
}

inline RigStitchInputs InputsFromFlight(const triangulation::SimulatedRigFlight& f) {
  RigStitchInputs in;
  in.positions = Uav4Positions();
  std::map<std::string, int> exposure, tie;
  for (const auto& e : f.exposures_file) {
    RigStitchExposure x;
    x.image = e.image;
    x.pose.rig_opk_rad = e.opk_rad;
    x.pose.rig_center_m = e.center_m;
    x.pose.velocity_mps = e.velocity_mps.value_or(Eigen::Vector3d::Zero());
    x.z_ref_m = *e.z_ref_m;
    exposure[e.image] = static_cast<int>(in.exposures.size());
    in.exposures.push_back(x);
  }
  for (const auto& p : f.points_file) {
    tie[p.id] = static_cast<int>(in.ties.size());
    in.ties.push_back({p.id, p.role == triangulation::PointRole::kCheck});
  }
  for (const auto& o : f.observations)
    in.observations.push_back({exposure.at(o.image),
                               f.truth.HeadIndex(o.head),
                               tie.at(o.point),
                               o.pixel,
                               o.sigma_px,
                               o.image + "/" + o.head + "/" + o.point});
  return in;
}

/// The floor of the per-coordinate pair metric over the fitted ties (virtual px):
/// `truth_parameters`: the metric with the simulator's TRUE increments and offsets (what a perfect
/// adjustment would leave: tie noise, relief off the plane, POS noise); `noise_prediction`: the
/// tie noise alone, propagated, sqrt(sum_pairs sigma^2 (|J_a|_F^2 + |J_b|_F^2) / (2 n_pairs)) with
/// J the 2 x 2 Jacobian of the head pixel -> virtual pixel map: two rays per pair (sqrt 2) at the
/// tilted heads' scale (a head pixel covers more than one virtual pixel).
struct PairMetricFloor {
  double truth_parameters = 0.0, noise_prediction = 0.0, mean_scale = 0.0;
};

inline PairMetricFloor PairFloor(const triangulation::SimulatedRigFlight& f,
                                 const RigStitchInputs& in) {
  const int n_heads = static_cast<int>(f.truth.heads.size());
  std::map<std::pair<int, int>, std::vector<int>> ties;
  for (int o = 0; o < static_cast<int>(in.observations.size()); ++o)
    if (!in.ties[in.observations[o].tie].check)
      ties[{in.observations[o].exposure, in.observations[o].tie}].push_back(o);
  double sum2 = 0.0, predicted = 0.0, scale = 0.0;
  int pairs = 0, rays = 0;
  for (int i = 0; i < static_cast<int>(in.exposures.size()); ++i) {
    RigExposure pose = in.exposures[i].pose;
    for (int k = 0; k < n_heads; ++k) {
      pose.increment_rad.push_back(f.rig_exposures[i * n_heads + k].increment_rad);
      pose.dt_s.push_back(f.rig_exposures[i * n_heads + k].dt_s);
    }
    const RigConverter converter(
        f.truth, pose, {Eigen::Vector3d::UnitZ(), in.exposures[i].z_ref_m});
    for (auto it = ties.lower_bound({i, -1}); it != ties.end() && it->first.first == i; ++it) {
      std::vector<Eigen::Vector2d> v;
      std::vector<double> j2;  // sigma^2 |J|_F^2 per ray
      for (int o : it->second) {
        const RigStitchObservation& ob = in.observations[o];
        const auto p = converter.VirtualFromHead(ob.head, ob.pixel);
        const auto pc = converter.VirtualFromHead(ob.head, ob.pixel + Eigen::Vector2d(0.5, 0));
        const auto pr = converter.VirtualFromHead(ob.head, ob.pixel + Eigen::Vector2d(0, 0.5));
        if (!p || !pc || !pr) continue;
        const double f2 = ((*pc - *p) / 0.5).squaredNorm() + ((*pr - *p) / 0.5).squaredNorm();
        v.push_back(*p);
        j2.push_back(ob.sigma_px * ob.sigma_px * f2);
        scale += std::sqrt(f2 / 2.0);
        ++rays;
      }
      for (size_t a = 0; a < v.size(); ++a)
        for (size_t b = a + 1; b < v.size(); ++b) {
          sum2 += (v[a] - v[b]).squaredNorm();
          predicted += j2[a] + j2[b];
          ++pairs;
        }
    }
  }
  return {std::sqrt(sum2 / (2.0 * pairs)), std::sqrt(predicted / (2.0 * pairs)), scale / rays};
}

}  // namespace aerocal::stitch::testing
