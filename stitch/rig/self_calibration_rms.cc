// The figures of the self-calibrating rig stitching (self_calibration_problem.h): the stitching
// RMS before and after (self_calibration.h header: per_coordinate and pair_2d over the pairs of a
// tie's virtual pixels), the standard positions' ties, the relief displacement, sigma0 in px.
#include "stitch/rig/self_calibration_problem.h"

#include <algorithm>
#include <cmath>

namespace aerocal::stitch::internal {
namespace {

// Sums of squared pair differences, by (fit | check).
struct RmsSums {
  double sum2[2] = {0, 0};
  int pairs[2] = {0, 0};
  int ties[2] = {0, 0};
  StitchRmsSet Finish() const {
    StitchRmsSet set;
    for (int c = 0; c < 2; ++c) {
      StitchRms& r = c == 0 ? set.fit : set.check;
      r.pairs = pairs[c];
      r.ties = ties[c];
      r.pair_2d = pairs[c] > 0 ? std::sqrt(sum2[c] / pairs[c]) : NAN;
      r.per_coordinate = pairs[c] > 0 ? std::sqrt(sum2[c] / (2.0 * pairs[c])) : NAN;
    }
    return set;
  }
};

// The observations of each tie that enter the comparison: every one of a check tie, the active
// (not rejected) ones of a fitted tie.
std::map<TieKey, std::vector<int>> ComparedObservations(const RigStitchProblem& p) {
  std::map<TieKey, std::vector<int>> used;
  for (const auto& [key, obs] : p.tie_observations) {
    if (p.ties[key.second].check) {
      used[key] = obs;
      continue;
    }
    const auto it = p.residuals_of_tie.find(key);
    if (it == p.residuals_of_tie.end()) continue;
    for (size_t j = 0; j < it->second.size(); ++j)  // residuals were added in observation order
      if (p.builder.IsActive(it->second[j])) used[key].push_back(obs[j]);
  }
  return used;
}

// The sums one phase (before | after) adds to: the flight's and the flight's zones'.
struct FlightSums {
  RmsSums flight;
  std::map<std::string, RmsSums> zones;
};

// The sums of one exposure at one phase, added to its exposure result and to the flight's.
void AddExposure(const RigStitchProblem& p,
                 const std::map<TieKey, std::vector<int>>& used,
                 const RigConverter& converter,
                 int i,
                 bool after,
                 FlightSums* flight,
                 RigStitchExposureResult* er) {
  RmsSums sums;
  std::map<std::string, RmsSums> exposure_zones;
  for (auto it = used.lower_bound({i, -1}); it != used.end() && it->first.first == i; ++it) {
    const int c = p.ties[it->first.second].check ? 1 : 0;
    std::vector<Eigen::Vector2d> v;
    unsigned mask = 0;
    for (int o : it->second)
      if (const auto px =
              converter.VirtualFromHead(p.observations[o].head, p.observations[o].pixel)) {
        v.push_back(*px);
        mask |= 1u << p.observations[o].head;
      }
    if (v.size() < 2) continue;
    const std::string zone = ZoneName(p.rig, mask);
    RmsSums* targets[] = {&sums, &exposure_zones[zone], &flight->flight, &flight->zones[zone]};
    for (RmsSums* s : targets) ++s->ties[c];
    for (size_t a = 0; a < v.size(); ++a)
      for (size_t b = a + 1; b < v.size(); ++b)
        for (RmsSums* s : targets) {
          s->sum2[c] += (v[a] - v[b]).squaredNorm();
          ++s->pairs[c];
        }
  }
  (after ? er->after : er->before) = sums.Finish();
  for (const auto& [zone, s] : exposure_zones) {
    auto z = std::find_if(er->zones.begin(),
                          er->zones.end(),
                          [&zone = zone](const ZoneStitchRms& r) { return r.zone == zone; });
    if (z == er->zones.end()) z = er->zones.insert(er->zones.end(), ZoneStitchRms{zone, {}, {}});
    (after ? z->after : z->before) = s.Finish();
  }
}

}  // namespace

void StitchingRms(RigStitchProblem& p, const std::vector<RigExposure>& refined) {
  const std::map<TieKey, std::vector<int>> used = ComparedObservations(p);
  FlightSums phases[2];  // before, after
  for (int phase = 0; phase < 2; ++phase)
    for (int i = 0; i < p.n_exposures; ++i) {
      const RigConverter converter(
          p.rig, phase == 0 ? p.poses[i] : refined[i], LevelPlane(p.exposures[i].z_ref_m));
      AddExposure(p, used, converter, i, phase == 1, &phases[phase], &p.result.exposures[i]);
    }
  p.result.before = phases[0].flight.Finish();
  p.result.after = phases[1].flight.Finish();
  // Every zone of the flight, in name order, with both phases (a zone seen in one phase only has
  // empty sums in the other).
  std::map<std::string, std::pair<RmsSums, RmsSums>> zone_sums;
  for (int phase = 0; phase < 2; ++phase)
    for (const auto& [zone, s] : phases[phase].zones)
      (phase == 0 ? zone_sums[zone].first : zone_sums[zone].second) = s;
  for (const auto& [zone, s] : zone_sums)
    p.result.zones.push_back({zone, s.first.Finish(), s.second.Finish()});
}

void CountStandardPositions(RigStitchProblem& p) {
  for (const auto& [where, keys] : p.position_ties) {
    StandardPositionCount count{p.exposures[where.first].image,
                                p.positions[where.second].name,
                                static_cast<int>(keys.size()),
                                0};
    for (const TieKey& key : keys) count.ties_after += TieAlive(p, key, {});
    p.result.standard_positions.push_back(count);
  }
}

void ReliefDisplacement(RigStitchProblem& p) {
  double height_sum = 0.0;
  for (const auto& e : p.exposures) height_sum += e.pose.rig_center_m.z() - e.z_ref_m;
  const double height_m = p.n_exposures > 0 ? height_sum / p.n_exposures : 0.0;
  p.result.height_m = height_m;
  const double relief_m = p.options.relief_m;
  if (!(relief_m > 0 && relief_m < height_m)) return;
  for (int j = 0; j < p.n_heads; ++j)
    for (int k = j + 1; k < p.n_heads; ++k)
      p.result.relief_displacement_px = std::max(
          p.result.relief_displacement_px, ReliefDisplacementPx(p.rig, j, k, height_m, relief_m));
}

// The median is the upper middle value of an even count (not calib/core/median.h's mean of the
// two): the figures written since issue 16 keep their values.
void Sigma0InPixels(RigStitchProblem& p) {
  std::vector<double> sigmas;
  for (const auto& [key, ids] : p.residuals_of_tie)
    for (int o : p.tie_observations.at(key)) sigmas.push_back(p.observations[o].sigma_px);
  if (sigmas.empty()) return;
  std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
  p.result.sigma0_px = p.result.sigma0 * sigmas[sigmas.size() / 2];
}

}  // namespace aerocal::stitch::internal
