#include "stitch/rig/self_calibration.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/problem/data_snooping.h"
#include "calib/problem/mounted_block.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/prior.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <set>

namespace aerocal::stitch {
namespace {

using TieKey = std::pair<int, int>;  // (exposure, tie)

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

RectificationPlane LevelPlane(double z_ref_m) { return {Eigen::Vector3d::UnitZ(), z_ref_m}; }

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

std::optional<RigStitchMode> ParseRigStitchMode(const std::string& name) {
  if (name == "line") return RigStitchMode::kLine;
  if (name == "per-exposure") return RigStitchMode::kPerExposure;
  if (name == "angles") return RigStitchMode::kAngles;
  return std::nullopt;
}

const char* RigStitchModeName(RigStitchMode mode) {
  switch (mode) {
    case RigStitchMode::kLine:
      return "line";
    case RigStitchMode::kPerExposure:
      return "per-exposure";
    case RigStitchMode::kAngles:
      return "angles";
  }
  return "?";
}

RigStitchResult SelfCalibrateRigStitching(const calib::Rig& rig,
                                          const std::vector<RigStitchExposure>& exposures,
                                          const std::vector<RigStitchTie>& ties,
                                          const std::vector<RigStitchObservation>& observations,
                                          const std::vector<StandardPosition>& positions,
                                          const RigStitchOptions& options) {
  AEROCAL_CHECK(rig.virtual_camera.orientation == calib::VirtualOrientation::kLevel)
      << "the self-calibrating stitching makes the level (horizontal) virtual image";
  const int n_heads = static_cast<int>(rig.heads.size());
  const int n_exposures = static_cast<int>(exposures.size());
  const int reference = rig.ReferenceIndex();
  RigStitchResult result;
  const Clock::time_point call_start = Clock::now();

  // Observations of each (exposure, tie).
  std::map<TieKey, std::vector<int>> tie_observations;
  for (int o = 0; o < static_cast<int>(observations.size()); ++o)
    tie_observations[{observations[o].exposure, observations[o].tie}].push_back(o);

  // Parameter storage (stable addresses).
  std::deque<Eigen::Vector3d> vectors;
  std::deque<double> scalars;
  calib::ProblemBuilder builder;
  std::vector<calib::BlockId> interior(n_heads), mount(n_heads), lever(n_heads);
  std::vector<calib::RigHead> heads = rig.heads;  // owned copies the blocks point into
  for (int k = 0; k < n_heads; ++k) {
    const std::string& id = heads[k].id;
    interior[k] = builder.AddBlock("interior[" + id + "]",
                                   heads[k].camera.interior.data(),
                                   heads[k].camera.interior.size(),
                                   calib::BlockKind::kInterior);
    mount[k] = builder.AddBlock(
        "mount[" + id + "]", heads[k].mount_rad.data(), 3, calib::BlockKind::kOther);
    lever[k] = builder.AddBlock(
        "lever_arm[" + id + "]", heads[k].lever_arm_m.data(), 3, calib::BlockKind::kOther);
    for (calib::BlockId b : {interior[k], mount[k], lever[k]}) builder.FixBlock(b);
  }
  const calib::BlockId zero_increment =
      builder.AddBlock("E[reference]",
                       vectors.emplace_back(Eigen::Vector3d::Zero()).data(),
                       3,
                       calib::BlockKind::kOther);
  const calib::BlockId zero_dt =
      builder.AddBlock("dT[reference]", &scalars.emplace_back(0.0), 1, calib::BlockKind::kOther);
  builder.FixBlock(zero_increment);
  builder.FixBlock(zero_dt);

  bool any_velocity = false;
  for (const auto& e : exposures) any_velocity |= e.pose.velocity_mps.norm() > 1e-9;
  result.dt_held = options.mode == RigStitchMode::kAngles || !any_velocity || options.hold_heads;
  if (!any_velocity && options.mode != RigStitchMode::kAngles)
    result.warnings.push_back(
        {"no_platform_velocity",
         "time offsets",
         NAN,
         NAN,
         "no platform velocity in the exposures: the time offsets move no head and are held at 0"});

  std::vector<calib::BlockId> rig_opk(n_exposures), rig_center(n_exposures);
  std::vector<std::vector<calib::BlockId>> increment(n_exposures,
                                                     std::vector<calib::BlockId>(n_heads, -1));
  std::vector<std::vector<calib::BlockId>> dt(n_exposures,
                                              std::vector<calib::BlockId>(n_heads, -1));
  std::vector<calib::BlockId> line_dt(n_heads, -1);
  std::vector<RigExposure> poses(n_exposures);
  std::vector<Eigen::Vector4d> rig_quaternion(n_exposures);  // sized once: blocks point into it
  const std::vector<std::string> angle_names = {"domega", "dphi", "dkappa"};
  for (int k = 0; k < n_heads; ++k) {
    if (k == reference || options.mode != RigStitchMode::kLine) continue;
    line_dt[k] = builder.AddBlock(
        "dT[" + heads[k].id + "]", &scalars.emplace_back(0.0), 1, calib::BlockKind::kOther, {"dT"});
    if (result.dt_held) builder.FixBlock(line_dt[k]);
  }
  for (int i = 0; i < n_exposures; ++i) {
    poses[i] = exposures[i].pose;
    poses[i].increment_rad.assign(n_heads, Eigen::Vector3d::Zero());
    poses[i].dt_s.assign(n_heads, 0.0);
    const std::string& image = exposures[i].image;
    // The exposure's POS attitude as the quaternion block the head residual takes (held).
    rig_quaternion[i] = calib::QuaternionFromOpk(poses[i].rig_opk_rad);
    rig_opk[i] = builder.AddRotationBlock("rig_opk[" + image + "]", rig_quaternion[i].data());
    rig_center[i] = builder.AddBlock(
        "rig_center[" + image + "]", poses[i].rig_center_m.data(), 3, calib::BlockKind::kOther);
    builder.FixBlock(rig_opk[i]);
    builder.FixBlock(rig_center[i]);
    for (int k = 0; k < n_heads; ++k) {
      if (k == reference) {
        increment[i][k] = zero_increment;
        dt[i][k] = zero_dt;
        continue;
      }
      const std::string name = image + "/" + heads[k].id;
      increment[i][k] = builder.AddBlock("E[" + name + "]",
                                         vectors.emplace_back(Eigen::Vector3d::Zero()).data(),
                                         3,
                                         calib::BlockKind::kOther,
                                         angle_names);
      if (options.hold_heads) builder.FixBlock(increment[i][k]);
      if (options.mode == RigStitchMode::kLine) {
        dt[i][k] = line_dt[k];
      } else {
        dt[i][k] = builder.AddBlock(
            "dT[" + name + "]", &scalars.emplace_back(0.0), 1, calib::BlockKind::kOther, {"dT"});
        if (result.dt_held) builder.FixBlock(dt[i][k]);
      }
      // Weighted around zero (calib/problem/mounted_block.h, group rig_stitch_prior); a held
      // increment keeps its prior, as it always has (it counts in the redundancy).
      if (options.increment_sigma_rad) {
        const double s = *options.increment_sigma_rad;
        calib::AddBlockPrior(builder,
                             increment[i][k],
                             calib::BlockMode::kWeighted,
                             {0, 0, 0},
                             {s, s, s},
                             kRigStitchOwner,
                             "prior E[" + name + "]");
      }
      if (options.dt_sigma_s && !result.dt_held &&
          (options.mode == RigStitchMode::kPerExposure || i == 0))
        calib::AddBlockPrior(builder,
                             dt[i][k],
                             calib::BlockMode::kWeighted,
                             {0},
                             {*options.dt_sigma_s},
                             kRigStitchOwner,
                             "prior " + builder.BlockName(dt[i][k]));
    }
  }

  // Ground calibration converters (E = I, dT = 0): tie starts, zones, standard positions.
  std::vector<RigConverter> ground_calibration;
  for (int i = 0; i < n_exposures; ++i)
    ground_calibration.emplace_back(rig, exposures[i].pose, LevelPlane(exposures[i].z_ref_m));

  // Fitted ties: a ground point on the plane, Z held.
  std::map<TieKey, int> position_of;  // tie -> standard position index
  std::map<std::pair<int, int>, std::vector<TieKey>> position_ties;  // (exposure, position)
  std::map<int, TieKey> tie_of_residual;
  std::map<TieKey, std::vector<calib::ResidualId>> residuals_of_tie;
  for (const auto& [key, obs] : tie_observations) {
    const auto [i, t] = key;
    if (ties[t].check) continue;
    std::set<int> seen;
    for (int o : obs) seen.insert(observations[o].head);
    if (seen.size() < 2) {
      ++result.dropped_ties;
      continue;
    }
    const RigConverter& converter = ground_calibration[i];
    std::optional<Eigen::Vector3d> start;
    Eigen::Vector2d mean_px = Eigen::Vector2d::Zero();
    unsigned mask = 0;
    int n_virtual = 0;
    for (int o : obs) {
      const RigStitchObservation& ob = observations[o];
      if (!start) start = converter.PlanePointOfHeadPixel(ob.head, ob.pixel);
      if (const auto v = converter.VirtualFromHead(ob.head, ob.pixel)) {
        mean_px += *v;
        ++n_virtual;
      }
      mask |= 1u << ob.head;
    }
    if (!start) {
      ++result.dropped_ties;
      continue;
    }
    Eigen::Vector3d& point = vectors.emplace_back(*start);
    point.z() = exposures[i].z_ref_m;
    const calib::BlockId point_block =
        builder.AddBlock("tie[" + exposures[i].image + "/" + ties[t].id + "]",
                         point.data(),
                         3,
                         calib::BlockKind::kGroundPoint,
                         {"X", "Y", "Z"});
    builder.FixEntries(point_block, {2});
    for (int o : obs) {
      const RigStitchObservation& ob = observations[o];
      const int k = ob.head;
      const calib::ResidualId id = builder.AddResidual(
          kGroupRigStitchTie,
          calib::MakeRigHeadCollinearityResidual(heads[k].camera.model,
                                                 heads[k].camera.frame(),
                                                 ob.pixel,
                                                 ob.sigma_px,
                                                 exposures[i].pose.velocity_mps),
          {interior[k],
           rig_opk[i],
           rig_center[i],
           mount[k],
           lever[k],
           increment[i][k],
           dt[i][k],
           point_block},
          ob.label.empty() ? ties[t].id + "@" + heads[k].id : ob.label);
      tie_of_residual[id] = key;
      residuals_of_tie[key].push_back(id);
    }
    // Its standard position: the nearest one of its zone within the radius.
    if (n_virtual > 0) {
      mean_px /= n_virtual;
      const std::string zone = ZoneName(rig, mask);
      int best = -1;
      double best_d = options.standard_radius_px;
      for (int s = 0; s < static_cast<int>(positions.size()); ++s) {
        const double d = (positions[s].virtual_px - mean_px).norm();
        if (positions[s].zone == zone && d <= best_d) {
          best = s;
          best_d = d;
        }
      }
      if (best >= 0) {
        position_of[key] = best;
        position_ties[{i, best}].push_back(key);
      }
    }
  }

  // A tie survives a removal when two or more of its observations stay.
  const auto alive = [&](const TieKey& key, const std::set<calib::ResidualId>& removed) {
    int left = 0;
    for (calib::ResidualId id : residuals_of_tie[key])
      left += builder.IsActive(id) && !removed.count(id);
    return left >= 2;
  };
  const auto veto = [&](const std::vector<calib::ResidualId>& ids) -> std::string {
    const std::set<calib::ResidualId> removed(ids.begin(), ids.end());
    for (calib::ResidualId id : ids) {
      const auto it = tie_of_residual.find(id);
      if (it == tie_of_residual.end()) continue;
      const auto pos = position_of.find(it->second);
      if (pos == position_of.end()) continue;
      const int i = it->second.first;
      bool any = false;
      for (const TieKey& other : position_ties[{i, pos->second}]) any |= alive(other, removed);
      if (!any) {
        const std::string reason = "standard position " + positions[pos->second].name +
                                   " of exposure " + exposures[i].image +
                                   " would lose all its ties (removing " +
                                   builder.ResidualLabel(id) + ")";
        result.stop_reasons.push_back(reason);
        return reason;
      }
    }
    return "";
  };

  std::vector<calib::ResidualId> kept_against_test;  // vetoed removals: the stop's suspects
  if (options.snooping) {
    calib::SnoopingOptions snooping;
    snooping.groups = {kGroupRigStitchTie};
    snooping.alpha = options.alpha;
    snooping.veto = veto;
    const calib::SnoopingOutcome outcome =
        calib::SolveWithDataSnooping(builder, options.solver, snooping);
    result.report = outcome.report;
    result.profile.solves = outcome.solves;
    result.profile.iterations = outcome.solve_iterations;
    result.profile.snooping_rounds = outcome.rounds;
    result.profile.solve_s = outcome.seconds_solving;
    result.profile.testing_s = outcome.seconds_testing;
    for (const auto& r : outcome.rejected) result.rejected.push_back(r.label);
    for (const auto& t : outcome.tested)
      if (t.verdict == calib::SnoopingVerdict::kVetoed) {
        result.stopped = true;
        kept_against_test.push_back(t.id);
      }
    for (const auto& f : outcome.findings)
      result.warnings.push_back({"data_snooping", "ties", NAN, NAN, f});
  } else {
    result.report = builder.Solve(options.solver);
    result.profile = {1, result.report.iterations, 0, result.report.seconds};
  }
  std::sort(result.stop_reasons.begin(), result.stop_reasons.end());
  result.stop_reasons.erase(std::unique(result.stop_reasons.begin(), result.stop_reasons.end()),
                            result.stop_reasons.end());
  result.sigma0 = result.report.sigma0;
  result.redundancy = result.report.redundancy;

  // Covariance of the increments and offsets.
  std::vector<calib::BlockId> wanted;
  for (int i = 0; i < n_exposures; ++i)
    for (int k = 0; k < n_heads; ++k)
      if (k != reference) {
        wanted.push_back(increment[i][k]);
        if (!builder.IsBlockFixed(dt[i][k]) &&
            std::find(wanted.begin(), wanted.end(), dt[i][k]) == wanted.end())
          wanted.push_back(dt[i][k]);
      }
  Clock::time_point start = Clock::now();
  const calib::CovarianceReport cov = builder.EstimateCovariance(
      wanted, std::max(result.sigma0, 1e-300), options.correlation_threshold);
  result.profile.covariance_s = SecondsSince(start);
  start = Clock::now();
  if (!cov.ok)
    result.warnings.push_back(
        {"covariance", "increments and time offsets", NAN, NAN, "covariance: " + cov.message});
  if (result.stopped)  // what the rig's calibration becomes without the ties kept against the test
    result.stop_effect = calib::EffectOfLeavingOut(builder,
                                                   kept_against_test,
                                                   cov,
                                                   wanted,
                                                   wanted,
                                                   options.solver,
                                                   options.suspect_effect_limit);
  result.profile.effect_s = SecondsSince(start);
  // The largest |rho| of each free dT with an angle of its head (each exposure for line mode).
  std::map<calib::BlockId, DtCorrelation> worst;
  std::set<calib::BlockId> undetermined_dt;
  if (cov.ok)
    for (int i = 0; i < n_exposures; ++i)
      for (int k = 0; k < n_heads; ++k) {
        if (k == reference || builder.IsBlockFixed(dt[i][k])) continue;
        const int row_dt = cov.offsets.at(dt[i][k]);
        for (int a = 0; a < 3; ++a) {
          const double rho = cov.Correlation(row_dt, cov.offsets.at(increment[i][k]) + a);
          DtCorrelation& w = worst[dt[i][k]];
          if (w.dt.empty() || std::abs(rho) > std::abs(w.rho))
            w = {builder.BlockName(dt[i][k]),
                 builder.BlockName(increment[i][k]) + "." + angle_names[a],
                 rho};
        }
      }
  for (const auto& [block, w] : worst) {
    result.dt_correlations.push_back(w);
    if (std::abs(w.rho) > options.correlation_threshold) {
      undetermined_dt.insert(block);
      result.dt_determinable = false;
    }
  }

  // Results per exposure and head.
  std::vector<RigExposure> refined = poses;
  for (int i = 0; i < n_exposures; ++i) {
    RigStitchExposureResult er;
    er.image = exposures[i].image;
    for (int k = 0; k < n_heads; ++k) {
      RigStitchHead h;
      h.head = heads[k].id;
      h.reference = k == reference;
      const double* e = builder.BlockValues(increment[i][k]);
      h.increment_rad = Eigen::Vector3d(e[0], e[1], e[2]);
      const double dt_value = *builder.BlockValues(dt[i][k]);
      h.dt_fitted_s = dt_value;
      refined[i].increment_rad[k] = h.increment_rad;
      refined[i].dt_s[k] = dt_value;
      if (!h.reference && cov.ok) h.increment_sigma_rad = cov.BlockSigma(increment[i][k], 3);
      if (h.reference || result.dt_held) {
        h.dt_s = dt_value;
      } else if (!undetermined_dt.count(dt[i][k])) {
        h.dt_s = dt_value;
        if (cov.ok) h.dt_sigma_s = cov.BlockSigma(dt[i][k], 1)[0];
      }
      er.heads.push_back(h);
    }
    result.exposures.push_back(er);
  }

  // Stitching RMS before (ground calibration) and after, over the active observations.
  std::map<TieKey, std::vector<int>> used;  // observations per tie in the comparison
  for (const auto& [key, obs] : tie_observations) {
    if (ties[key.second].check) {
      used[key] = obs;
      continue;
    }
    const auto it = residuals_of_tie.find(key);
    if (it == residuals_of_tie.end()) continue;
    for (size_t j = 0; j < it->second.size(); ++j)  // residuals were added in observation order
      if (builder.IsActive(it->second[j])) used[key].push_back(obs[j]);
  }
  std::map<std::string, std::pair<RmsSums, RmsSums>> zone_sums;  // flight: before, after
  RmsSums flight_before, flight_after;
  for (int phase = 0; phase < 2; ++phase) {
    for (int i = 0; i < n_exposures; ++i) {
      const RigConverter converter(
          rig, phase == 0 ? poses[i] : refined[i], LevelPlane(exposures[i].z_ref_m));
      RmsSums sums;
      std::map<std::string, RmsSums> exposure_zones;
      for (auto it = used.lower_bound({i, -1}); it != used.end() && it->first.first == i; ++it) {
        const int c = ties[it->first.second].check ? 1 : 0;
        std::vector<Eigen::Vector2d> v;
        unsigned mask = 0;
        for (int o : it->second)
          if (const auto p =
                  converter.VirtualFromHead(observations[o].head, observations[o].pixel)) {
            v.push_back(*p);
            mask |= 1u << observations[o].head;
          }
        if (v.size() < 2) continue;
        const std::string zone = ZoneName(rig, mask);
        RmsSums* targets[] = {&sums,
                              &exposure_zones[zone],
                              phase == 0 ? &flight_before : &flight_after,
                              phase == 0 ? &zone_sums[zone].first : &zone_sums[zone].second};
        for (RmsSums* s : targets) ++s->ties[c];
        for (size_t a = 0; a < v.size(); ++a)
          for (size_t b = a + 1; b < v.size(); ++b)
            for (RmsSums* s : targets) {
              s->sum2[c] += (v[a] - v[b]).squaredNorm();
              ++s->pairs[c];
            }
      }
      RigStitchExposureResult& er = result.exposures[i];
      (phase == 0 ? er.before : er.after) = sums.Finish();
      for (const auto& zone_rms : exposure_zones) {
        const std::string& zone = zone_rms.first;  // (a lambda may not capture a binding, C++17)
        const RmsSums& s = zone_rms.second;
        auto z = std::find_if(er.zones.begin(), er.zones.end(), [&](const ZoneStitchRms& r) {
          return r.zone == zone;
        });
        if (z == er.zones.end()) z = er.zones.insert(er.zones.end(), ZoneStitchRms{zone, {}, {}});
        (phase == 0 ? z->before : z->after) = s.Finish();
      }
    }
  }
  result.before = flight_before.Finish();
  result.after = flight_after.Finish();
  for (const auto& [zone, s] : zone_sums)
    result.zones.push_back({zone, s.first.Finish(), s.second.Finish()});

  // Standard positions: fitted ties before and after the snooping.
  for (const auto& [where, keys] : position_ties) {
    StandardPositionCount count{exposures[where.first].image,
                                positions[where.second].name,
                                static_cast<int>(keys.size()),
                                0};
    for (const TieKey& key : keys) count.ties_after += alive(key, {});
    result.standard_positions.push_back(count);
  }

  // The plane model's residual displacement for the relief (CONVENTIONS.md).
  double height_sum = 0.0;
  for (const auto& e : exposures) height_sum += e.pose.rig_center_m.z() - e.z_ref_m;
  const double height_m = n_exposures > 0 ? height_sum / n_exposures : 0.0;
  result.height_m = height_m;
  if (options.relief_m > 0 && options.relief_m < height_m)
    for (int j = 0; j < n_heads; ++j)
      for (int k = j + 1; k < n_heads; ++k)
        result.relief_displacement_px =
            std::max(result.relief_displacement_px,
                     ReliefDisplacementPx(rig, j, k, height_m, options.relief_m));

  std::vector<double> sigmas;
  for (const auto& [key, ids] : residuals_of_tie)
    for (int o : tie_observations[key]) sigmas.push_back(observations[o].sigma_px);
  if (!sigmas.empty()) {
    std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
    result.sigma0_px = result.sigma0 * sigmas[sigmas.size() / 2];
  }
  // What makes the run untrustworthy, by name.
  if (!result.report.converged)
    result.failures.push_back("the adjustment did not converge (" + result.report.termination +
                              ": " + result.report.message + ")");
  if (!cov.ok) result.failures.push_back("covariance not computable (singular): " + cov.message);
  if (!(result.sigma0 <= options.max_sigma0))
    result.failures.push_back(
        StringPrintf("sigma0 %.3g is above %.3g: the tie sigmas or the rig model are wrong",
                     result.sigma0,
                     options.max_sigma0));
  // A stop is judged by its effect: invalid when it matters, else a warning (issue 28 part 2).
  for (const auto& reason : result.stop_reasons) {
    const std::string message =
        "snooping stopped: " + reason + "; " + result.stop_effect.Describe();
    if (result.stop_effect.Matters())
      result.failures.push_back(message);
    else
      result.warnings.push_back({"snooping_stopped",
                                 reason,
                                 NAN,
                                 NAN,
                                 message + "; the tie is kept and the result stands: check it"});
  }
  result.profile.total_s = SecondsSince(call_start);
  return result;
}

}  // namespace aerocal::stitch
