#include "triangulation/simulation/rig_flight_simulator.h"

#include <cmath>
#include <cstdio>

#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "triangulation/block/block_io.h"

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kMarginPx = 20.0;  // points are measured at least this far inside a head's format
using Model = calib::Camera::Model;

calib::RigHead DualLensHead(const std::string& id, const Eigen::Vector3d& mount_deg,
                            const Eigen::Vector3d& lever_arm_m) {
  calib::RigHead head;
  head.id = id;
  head.camera.name = id;
  head.camera.pixel_size_mm = 0.006;
  head.camera.width_px = 10000;
  head.camera.height_px = 10000;
  head.camera.interior[Model::kC] = 150.0;
  head.camera.interior[Model::kX0] = 3.0;
  head.camera.interior[Model::kY0] = 3.0;
  head.mount_rad = mount_deg * kDegToRad;
  head.lever_arm_m = lever_arm_m;
  return head;
}

}  // namespace

std::optional<RigPreset> ParseRigPreset(const std::string& name) {
  if (name == "dual-lens") return RigPreset::kDualLens;
  if (name == "uav4") return RigPreset::kUav4;
  return std::nullopt;
}

calib::Rig MakeNominalRig(RigPreset preset) {
  if (preset != RigPreset::kDualLens)
    throw ConfigError("--rig uav4: the four-head UAV rig is not built yet (the four-head issue, 16); use dual-lens");
  // configs/rig_dual_lens.yaml (a test checks that both agree).
  calib::Rig rig;
  rig.name = "dual-lens-150";
  rig.reference_head = "A";
  calib::VirtualCamera& v = rig.virtual_camera;
  v.orientation = calib::VirtualOrientation::kRig;
  v.c_mm = 150.0;
  v.pixel_size_mm = 0.006;
  v.width_px = 10460;
  v.height_px = 10044;
  v.x0_mm = 4.374;
  v.y0_mm = 3.006;
  v.height_m = 1200.0;
  rig.heads.push_back(DualLensHead("A", Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()));
  rig.heads.push_back(DualLensHead("B", {0.0, 1.0, 0.0}, {0.15, 0.01, 0.01}));
  return rig;
}

FlightSimulationOptions RigFlightSimulationOptions::DefaultRigFlight() {
  FlightSimulationOptions o;
  o.flying_height_m = 1200.0;
  o.terrain_relief_m = 100.0;
  o.exposures = 30;
  o.strips = 3;
  o.ground_points = 40;
  o.control_points = 5;
  o.tie_points = 300;
  o.start_position_error_m = 5.0;
  return o;
}

std::vector<calib::InteriorParams> RigFlightSimulationOptions::DefaultHeadInteriorCorrections() {
  // Of the size a laboratory calibration leaves: c 20 um, principal point a few um, distortion
  // of a fraction of a pixel at the format corner (r = 46 mm).
  calib::InteriorParams a{}, b{};
  a[Model::kC] = 0.020;
  a[Model::kX0] = -0.003;
  a[Model::kY0] = 0.002;
  a[Model::kK1] = 2.0e-8;
  a[Model::kP1] = 1.0e-7;
  a[Model::kB1] = 5.0e-6;
  b[Model::kC] = -0.015;
  b[Model::kX0] = 0.002;
  b[Model::kY0] = 0.004;
  b[Model::kK1] = -1.5e-8;
  b[Model::kP2] = -1.0e-7;
  b[Model::kB2] = 4.0e-6;
  return {a, b};
}

bool ProjectRigHead(const calib::RigHead& head, const Exposure& exposure,
                    const RigExposureTruth& increment, const Eigen::Vector3d& point_m,
                    Eigen::Vector2d* pixel) {
  const Eigen::Vector3d velocity = exposure.velocity_mps.value_or(Eigen::Vector3d::Zero());
  double rotation[9], center[3];
  calib::HeadPose(exposure.opk_rad.data(), exposure.center_m.data(), head.mount_rad.data(),
                  head.lever_arm_m.data(), increment.increment_rad.data(), &increment.dt_s,
                  velocity.data(), rotation, center);
  const Eigen::Matrix3d object_from_head =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation);
  return head.camera.ProjectToPixel(calib::OpkFromRotation(object_from_head),
                                    Eigen::Vector3d(center[0], center[1], center[2]), point_m,
                                    pixel);
}

SimulatedRigFlight SimulateRigFlight(const RigFlightSimulationOptions& options) {
  const FlightSimulationOptions& o = options.flight;
  if (o.exposures < 2 || o.strips < 1 || o.exposures < o.strips)
    throw ConfigError("a flight needs at least 2 exposures and one strip per exposure row");
  if (!(options.increment_sigma_rad >= 0) || !(std::abs(options.time_offset_s) <= 1.0) ||
      !(options.speed_mps >= 0))
    throw ConfigError("rig simulation: increment sigma and speed must be >= 0, |dT| <= 1 s");
  internal::SimulationRandom random(o.seed);
  auto& rng = random.rng;
  auto& normal = random.normal;

  SimulatedRigFlight f;
  f.options = options;
  f.nominal = MakeNominalRig(options.preset);
  f.truth = f.nominal;
  f.truth.name = f.nominal.name + " (truth)";
  const int reference = f.truth.ReferenceIndex();
  for (size_t k = 0; k < f.truth.heads.size(); ++k) {
    calib::RigHead& head = f.truth.heads[k];
    const auto& correction = options.interior_correction.empty()
                                 ? calib::InteriorParams{}
                                 : options.interior_correction[std::min(
                                       k, options.interior_correction.size() - 1)];
    for (int i = 0; i < Model::kNumParams; ++i) head.camera.interior[i] += correction[i];
    if (static_cast<int>(k) == reference) continue;
    head.mount_rad += options.mount_error_rad;
    head.lever_arm_m += options.lever_arm_error_m;
  }

  const calib::VirtualCamera& v = f.nominal.virtual_camera;
  const double scale = o.flying_height_m / (v.c_mm * 1e-3);
  const Eigen::Vector2d footprint(v.width_px * v.pixel_size_mm * 1e-3 * scale,
                                  v.height_px * v.pixel_size_mm * 1e-3 * scale);
  f.exposures_truth = internal::PlanStrips(o, footprint, "rig1", random);
  if (options.speed_mps > 0)
    for (auto& e : f.exposures_truth)  // along the strip: kappa 0 flies +x, kappa 180 deg -x
      e.velocity_mps = Eigen::Vector3d(options.speed_mps * std::cos(e.opk_rad.z()),
                                       options.speed_mps * std::sin(e.opk_rad.z()), 0.0);
  f.exposures_file = internal::ExposuresAsMeasured(o, f.exposures_truth, random);
  for (const auto& e : f.exposures_truth) {
    for (size_t k = 0; k < f.truth.heads.size(); ++k) {
      RigExposureTruth t;
      t.image = e.image;
      t.head = f.truth.heads[k].id;
      if (static_cast<int>(k) != reference) {
        t.increment_rad = options.increment_sigma_rad *
                          Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
        t.dt_s = options.time_offset_s;
      }
      f.rig_exposures.push_back(t);
    }
  }
  const size_t heads = f.truth.heads.size();
  // Every head of exposure i that sees `point` inside its format (margin in px).
  const auto measure = [&](size_t i, const Eigen::Vector3d& point,
                           std::vector<std::pair<int, Eigen::Vector2d>>* seen) {
    seen->clear();
    for (size_t k = 0; k < heads; ++k) {
      const calib::RigHead& head = f.truth.heads[k];
      Eigen::Vector2d px;
      if (!ProjectRigHead(head, f.exposures_truth[i], f.rig_exposures[i * heads + k], point, &px))
        continue;
      if (px.x() < kMarginPx || px.y() < kMarginPx ||
          px.x() > head.camera.width_px - 1 - kMarginPx ||
          px.y() > head.camera.height_px - 1 - kMarginPx)
        continue;
      seen->push_back({static_cast<int>(k), px});
    }
  };
  std::vector<std::pair<int, Eigen::Vector2d>> seen;
  const auto seen_by = [&](const Eigen::Vector3d& p) {
    int exposures = 0;
    for (size_t i = 0; i < f.exposures_truth.size(); ++i) {
      measure(i, p, &seen);
      exposures += seen.empty() ? 0 : 1;
    }
    return exposures;
  };
  internal::PlacePoints(o, f.exposures_truth, footprint, seen_by, random, &f.points_truth,
                        &f.points_file);

  for (const auto& p : f.points_truth) {
    for (size_t i = 0; i < f.exposures_truth.size(); ++i) {
      measure(i, *p.xyz_m, &seen);
      for (const auto& [k, px] : seen) {
        ImageObservation obs;
        obs.image = f.exposures_truth[i].image;
        obs.head = f.truth.heads[k].id;
        obs.point = p.id;
        obs.sigma_px = o.image_sigma_px;
        obs.pixel = px + o.image_noise_px * Eigen::Vector2d(normal(rng), normal(rng));
        f.observations.push_back(obs);
      }
    }
  }
  return f;
}

void WriteSimulatedRigFlight(const SimulatedRigFlight& f, const std::string& folder) {
  const auto path = [&](const std::string& name) { return folder + "/" + name; };
  calib::WriteRig(path("rig_nominal.yaml"), f.nominal);
  calib::WriteRig(path("rig_truth.yaml"), f.truth);
  WriteExposures(path("exposures.csv"), f.exposures_file);
  WriteObservations(path("observations.csv"), f.observations);
  WritePoints(path("points.csv"), f.points_file);
  WriteExposures(path("truth/exposures.csv"), f.exposures_truth);
  WritePoints(path("truth/points.csv"), f.points_truth);
  WriteFileAtomically(path("truth/rig_exposures.csv"), [&](std::ostream& out) {
    out << "image,head,domega,dphi,dkappa,dT_ms\n";
    for (const auto& t : f.rig_exposures)
      out << t.image << "," << t.head << ","
          << StringPrintf("%.10f,%.10f,%.10f,%.6f", t.increment_rad.x() / kDegToRad,
                          t.increment_rad.y() / kDegToRad, t.increment_rad.z() / kDegToRad,
                          t.dt_s * 1e3)
          << "\n";
  });
  WriteFileAtomically(path("project.yaml"),
                      "# Simulated rig flight (aerocal simulate --rig, seed " +
                          std::to_string(f.options.flight.seed) +
                          ")\n"
                          "cameras: {rig1: rig_nominal.yaml}\n"
                          "exposures: exposures.csv\n"
                          "points: points.csv\n"
                          "observations: observations.csv\n"
                          "frame: {projected: \"simulated local frame\"}\n");
}

}  // namespace aerocal::triangulation
