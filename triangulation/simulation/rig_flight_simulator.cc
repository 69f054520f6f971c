#include "triangulation/simulation/rig_flight_simulator.h"

#include "calib/camera/rig_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "stitch/image_io/image_io.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/block/block_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kMarginPx = 20.0;  // points are measured at least this far inside a head's format
using Model = calib::Camera::Model;

calib::RigHead MakeHead(const std::string& id,
                        double pixel_size_mm,
                        int width_px,
                        int height_px,
                        const Eigen::Vector3d& c_x0_y0_mm,
                        const Eigen::Vector3d& mount_deg,
                        const Eigen::Vector3d& lever_arm_m) {
  calib::RigHead head;
  head.id = id;
  head.camera.name = id;
  head.camera.pixel_size_mm = pixel_size_mm;
  head.camera.width_px = width_px;
  head.camera.height_px = height_px;
  head.camera.interior[Model::kC] = c_x0_y0_mm.x();
  head.camera.interior[Model::kX0] = c_x0_y0_mm.y();
  head.camera.interior[Model::kY0] = c_x0_y0_mm.z();
  head.mount_rad = mount_deg * kDegToRad;
  head.lever_arm_m = lever_arm_m;
  return head;
}

calib::RigHead DualLensHead(const std::string& id,
                            const Eigen::Vector3d& mount_deg,
                            const Eigen::Vector3d& lever_arm_m) {
  return MakeHead(id, 0.006, 10000, 10000, {150.0, 3.0, 3.0}, mount_deg, lever_arm_m);
}

// configs/rig_uav4.yaml (a test checks that both agree).
calib::Rig Uav4Rig() {
  calib::Rig rig;
  rig.name = "uav4-24";
  rig.reference_head = "A";
  rig.virtual_camera =
      calib::VirtualCamera::Pinhole(calib::VirtualOrientation::kLevel, 24.5, 0.0082, 8660, 11760);
  rig.virtual_camera.height_m = 300.0;
  const Eigen::Vector3d interior(24.5, 0.0, 0.0);
  rig.heads.push_back(MakeHead("A", 0.0082, 2912, 4368, interior, {0, -24, 0}, {0.06, 0, 0}));
  rig.heads.push_back(MakeHead("B", 0.0082, 4368, 2912, interior, {37, 0, 0}, {0, 0.06, 0}));
  rig.heads.push_back(MakeHead("C", 0.0082, 2912, 4368, interior, {0, 24, 0}, {-0.06, 0, 0}));
  rig.heads.push_back(MakeHead("D", 0.0082, 4368, 2912, interior, {-37, 0, 0}, {0, -0.06, 0}));
  return rig;
}

// The point where the ray through a virtual pixel meets the terrain (bisection between planes
// below and above the terrain's range); false when the ray does not point down.
bool TerrainPointOfRay(const FlightSimulationOptions& o,
                       const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& direction,
                       Eigen::Vector3d* point,
                       int iterations = 80) {
  if (!(direction.z() < 0)) return false;
  const double z_lo = o.terrain_base_m - 1.0, z_hi = o.terrain_base_m + o.terrain_relief_m + 1.0;
  double s_lo = (origin.z() - z_hi) / -direction.z(), s_hi = (origin.z() - z_lo) / -direction.z();
  const auto above = [&](double s) {
    const Eigen::Vector3d p = origin + s * direction;
    return p.z() > SimulatedTerrainHeight(o, p.x(), p.y());
  };
  for (int i = 0; i < iterations; ++i) {
    const double mid = 0.5 * (s_lo + s_hi);
    (above(mid) ? s_lo : s_hi) = mid;
  }
  *point = origin + 0.5 * (s_lo + s_hi) * direction;
  point->z() = SimulatedTerrainHeight(o, point->x(), point->y());
  return true;
}

}  // namespace

std::optional<RigPreset> ParseRigPreset(const std::string& name) {
  if (name == "dual-lens") return RigPreset::kDualLens;
  if (name == "uav4") return RigPreset::kUav4;
  return std::nullopt;
}

calib::Rig MakeNominalRig(RigPreset preset) {
  if (preset == RigPreset::kUav4) return Uav4Rig();
  // configs/rig_dual_lens.yaml (a test checks that both agree).
  calib::Rig rig;
  rig.name = "dual-lens-150";
  rig.reference_head = "A";
  rig.virtual_camera = calib::VirtualCamera::Pinhole(
      calib::VirtualOrientation::kRig, 150.0, 0.006, 10460, 10044, 4.374, 3.006, 1200.0);
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

RigFlightSimulationOptions RigFlightSimulationOptions::DefaultUav4() {
  RigFlightSimulationOptions r;
  r.preset = RigPreset::kUav4;
  FlightSimulationOptions& o = r.flight;
  o.flying_height_m = 300.0;
  o.terrain_relief_m = 30.0;
  o.exposures = 8;
  o.strips = 1;
  o.ground_points = 0;
  o.control_points = 0;
  o.tie_points = 0;
  o.image_noise_px = 0.3;
  o.image_sigma_px = 0.3;
  o.gnss_sigma_m = 0.05;
  o.imu_sigma_deg = 0.01;
  r.increment_sigma_rad = 0.025 * kDegToRad;
  r.speed_mps = 10.0;
  r.head_time_offsets_s = {0.0, 0.003, -0.0025, 0.0035};
  r.stitch_ties.per_standard_position = 3;
  r.stitch_ties.dense = 40;
  r.stitch_ties.check = 10;
  return r;
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

bool ProjectRigHead(const calib::RigHead& head,
                    const Exposure& exposure,
                    const RigExposureTruth& increment,
                    const Eigen::Vector3d& point_m,
                    Eigen::Vector2d* pixel) {
  const Eigen::Vector3d velocity = exposure.velocity_mps.value_or(Eigen::Vector3d::Zero());
  double rotation[9], center[3];
  calib::HeadPose(exposure.opk_rad.data(),
                  exposure.center_m.data(),
                  head.mount_rad.data(),
                  head.lever_arm_m.data(),
                  increment.increment_rad.data(),
                  &increment.dt_s,
                  velocity.data(),
                  rotation,
                  center);
  const Eigen::Matrix3d object_from_head =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation);
  return head.camera.ProjectToPixel(calib::OpkFromRotation(object_from_head),
                                    Eigen::Vector3d(center[0], center[1], center[2]),
                                    point_m,
                                    pixel);
}

namespace {

using HeadPixels = std::vector<std::pair<int, Eigen::Vector2d>>;

// Every head of exposure i that sees `point` inside its format (kMarginPx from the border).
HeadPixels HeadsSeeing(const SimulatedRigFlight& f, size_t i, const Eigen::Vector3d& point) {
  const size_t heads = f.truth.heads.size();
  HeadPixels seen;
  for (size_t k = 0; k < heads; ++k) {
    const calib::RigHead& head = f.truth.heads[k];
    Eigen::Vector2d px;
    if (!ProjectRigHead(head, f.exposures_truth[i], f.rig_exposures[i * heads + k], point, &px))
      continue;
    if (px.x() < kMarginPx || px.y() < kMarginPx || px.x() > head.camera.width_px - 1 - kMarginPx ||
        px.y() > head.camera.height_px - 1 - kMarginPx)
      continue;
    seen.push_back({static_cast<int>(k), px});
  }
  return seen;
}

// The head observations of `point` in exposure i, with the flight's image noise.
void AddHeadObservations(SimulatedRigFlight& f,
                         size_t i,
                         const std::string& point,
                         const HeadPixels& seen,
                         internal::SimulationRandom& random) {
  const FlightSimulationOptions& o = f.options.flight;
  for (const auto& [k, px] : seen) {
    ImageObservation obs;
    obs.image = f.exposures_truth[i].image;
    obs.head = f.truth.heads[k].id;
    obs.point = point;
    obs.sigma_px = o.image_sigma_px;
    obs.pixel = px + o.image_noise_px *
                         Eigen::Vector2d(random.normal(random.rng), random.normal(random.rng));
    f.observations.push_back(obs);
  }
}

// The level virtual camera of exposure i with the rig's heading (CONVENTIONS.md), at O: the
// terrain point of a virtual pixel.
struct VirtualGround {
  const SimulatedRigFlight& f;
  const Exposure& e;
  Eigen::Matrix3d object_from_virtual;
  VirtualGround(const SimulatedRigFlight& flight, size_t i)
      : f(flight), e(flight.exposures_truth[i]) {
    const double kappa = calib::OpkFromRotation(calib::RotationFromOpk(e.opk_rad)).z();
    object_from_virtual = calib::RotationFromOpk({0.0, 0.0, kappa});
  }
  bool operator()(const Eigen::Vector2d& px, Eigen::Vector3d* g) const {
    const std::optional<Eigen::Vector3d> ray = f.nominal.virtual_camera.RayFromPixel(px);
    return ray && TerrainPointOfRay(f.options.flight, e.center_m, object_from_virtual * *ray, g);
  }
};

// z_ref: the mean terrain height under the virtual image (a 20 x 20 grid); nullopt where no ray
// meets the terrain.
std::optional<double> MeanTerrainHeight(const VirtualGround& ground_of, const calib::Camera& v) {
  double sum = 0.0;
  int n = 0;
  for (int r = 0; r < 20; ++r)
    for (int c = 0; c < 20; ++c) {
      Eigen::Vector3d g;
      if (ground_of({(c + 0.5) * v.width_px / 20.0, (r + 0.5) * v.height_px / 20.0}, &g)) {
        sum += g.z();
        ++n;
      }
    }
  if (n == 0) return std::nullopt;
  return sum / n;
}

// A stitching tie (or check tie) of exposure i at a virtual pixel: measured in every head that
// sees it (>= 2), without coordinates in the file. False where fewer than two heads see it.
bool PlaceTie(SimulatedRigFlight& f,
              size_t i,
              const VirtualGround& ground_of,
              const Eigen::Vector2d& px,
              PointRole role,
              const std::string& position,
              int* serial,
              internal::SimulationRandom& random) {
  Eigen::Vector3d g;
  if (!ground_of(px, &g)) return false;
  const HeadPixels seen = HeadsSeeing(f, i, g);
  if (seen.size() < 2) return false;
  GroundPoint truth;
  truth.id = StringPrintf("%s_%s%03d",
                          f.exposures_truth[i].image.c_str(),
                          role == PointRole::kCheck ? "c" : "t",
                          (*serial)++);
  truth.role = role;
  truth.xyz_m = g;
  GroundPoint file = truth;
  file.xyz_m.reset();  // a stitching tie (and a check tie) has no coordinates
  f.points_truth.push_back(truth);
  f.points_file.push_back(file);
  if (!position.empty()) f.tie_position[truth.id] = position;
  AddHeadObservations(f, i, truth.id, seen, random);
  return true;
}

// z_ref of every exposure and the stitching ties (header comment), drawn after everything else so
// that the flight, points and observations of a seed do not depend on them.
void AddStitchingTies(SimulatedRigFlight& f, internal::SimulationRandom& random) {
  const auto& st = f.options.stitch_ties;
  auto& rng = random.rng;
  auto& uniform = random.uniform;
  const calib::Camera& v = f.nominal.virtual_camera.camera;
  const bool any = st.dense > 0 || st.check > 0 ||
                   (st.per_standard_position > 0 && !st.standard_positions.empty());
  for (size_t i = 0; i < f.exposures_truth.size(); ++i) {
    const VirtualGround ground_of(f, i);
    if (const auto z_ref = MeanTerrainHeight(ground_of, v))
      f.exposures_truth[i].z_ref_m = f.exposures_file[i].z_ref_m = *z_ref;
    if (!any) continue;
    int serial = 0;
    const auto place = [&](const Eigen::Vector2d& px, PointRole role, const std::string& position) {
      return PlaceTie(f, i, ground_of, px, role, position, &serial, random);
    };
    for (const auto& s : st.standard_positions)
      for (int j = 0, tries = 0;
           j < st.per_standard_position && tries < 100 * st.per_standard_position + 100;
           ++tries) {
        const double radius = st.jitter_px * std::sqrt(uniform(rng)),
                     angle = 2 * M_PI * uniform(rng);
        j += place(s.virtual_px + radius * Eigen::Vector2d(std::cos(angle), std::sin(angle)),
                   PointRole::kTie,
                   s.name);
      }
    for (PointRole role : {PointRole::kTie, PointRole::kCheck}) {
      const int wanted = role == PointRole::kTie ? st.dense : st.check;
      for (int j = 0, tries = 0; j < wanted && tries < 1000 * wanted; ++tries)
        j += place({uniform(rng) * (v.width_px - 1), uniform(rng) * (v.height_px - 1)}, role, "");
    }
  }
}

void CheckRigSimulationOptions(const RigFlightSimulationOptions& options) {
  const FlightSimulationOptions& o = options.flight;
  if (o.exposures < 2 || o.strips < 1 || o.exposures < o.strips)
    throw ConfigError("a flight needs at least 2 exposures and one strip per exposure row");
  if (!(options.increment_sigma_rad >= 0) || !(std::abs(options.time_offset_s) <= 1.0) ||
      !(options.speed_mps >= 0))
    throw ConfigError("rig simulation: increment sigma and speed must be >= 0, |dT| <= 1 s");
  for (double dt : options.head_time_offsets_s)
    if (!(std::abs(dt) <= 1.0)) throw ConfigError("rig simulation: |dT| of every head <= 1 s");
  const auto& st = options.stitch_ties;
  if (st.per_standard_position < 0 || st.dense < 0 || st.check < 0 || !(st.jitter_px >= 0))
    throw ConfigError("rig simulation: stitching tie counts and jitter must be >= 0");
}

// The true rig: the nominal one with each head's interior correction and, for the non-reference
// heads, the mount and lever-arm errors.
calib::Rig TrueRig(const calib::Rig& nominal, const RigFlightSimulationOptions& options) {
  calib::Rig truth = nominal;
  truth.name = nominal.name + " (truth)";
  const int reference = truth.ReferenceIndex();
  for (size_t k = 0; k < truth.heads.size(); ++k) {
    calib::RigHead& head = truth.heads[k];
    const auto& correction =
        options.interior_correction.empty()
            ? calib::InteriorParams{}
            : options.interior_correction[std::min(k, options.interior_correction.size() - 1)];
    for (int i = 0; i < Model::kNumParams; ++i) head.camera.interior[i] += correction[i];
    if (static_cast<int>(k) == reference) continue;
    head.mount_rad += options.mount_error_rad;
    head.lever_arm_m += options.lever_arm_error_m;
  }
  return truth;
}

// The true increments and time offsets of every head and exposure (exposure-major), the reference
// head's held at zero.
void DrawRigExposures(SimulatedRigFlight& f, internal::SimulationRandom& random) {
  const RigFlightSimulationOptions& options = f.options;
  const int reference = f.truth.ReferenceIndex();
  for (const auto& e : f.exposures_truth) {
    for (size_t k = 0; k < f.truth.heads.size(); ++k) {
      RigExposureTruth t;
      t.image = e.image;
      t.head = f.truth.heads[k].id;
      if (static_cast<int>(k) != reference) {
        t.increment_rad = options.increment_sigma_rad * Eigen::Vector3d(random.normal(random.rng),
                                                                        random.normal(random.rng),
                                                                        random.normal(random.rng));
        t.dt_s =
            options.head_time_offsets_s.empty()
                ? options.time_offset_s
                : options.head_time_offsets_s[std::min(k, options.head_time_offsets_s.size() - 1)];
      }
      f.rig_exposures.push_back(t);
    }
  }
}

}  // namespace

SimulatedRigFlight SimulateRigFlight(const RigFlightSimulationOptions& options) {
  CheckRigSimulationOptions(options);
  const FlightSimulationOptions& o = options.flight;
  internal::SimulationRandom random(o.seed);
  SimulatedRigFlight f;
  f.options = options;
  f.nominal = ScaleRigFormats(MakeNominalRig(options.preset), options.format_scale);
  f.truth = TrueRig(f.nominal, options);

  const calib::Camera& v = f.nominal.virtual_camera.camera;
  const double scale = o.flying_height_m / (v.c_mm() * 1e-3);
  const Eigen::Vector2d footprint(v.width_px * v.pixel_size_mm * 1e-3 * scale,
                                  v.height_px * v.pixel_size_mm * 1e-3 * scale);
  f.exposures_truth = internal::PlanStrips(o, footprint, "rig1", random);
  if (options.speed_mps > 0)
    for (auto& e : f.exposures_truth)  // along the strip: kappa 0 flies +x, kappa 180 deg -x
      e.velocity_mps = Eigen::Vector3d(options.speed_mps * std::cos(e.opk_rad.z()),
                                       options.speed_mps * std::sin(e.opk_rad.z()),
                                       0.0);
  f.exposures_file = internal::ExposuresAsMeasured(o, f.exposures_truth, random);
  DrawRigExposures(f, random);
  const auto seen_by = [&](const Eigen::Vector3d& p) {
    int exposures = 0;
    for (size_t i = 0; i < f.exposures_truth.size(); ++i)
      exposures += HeadsSeeing(f, i, p).empty() ? 0 : 1;
    return exposures;
  };
  internal::PlacePoints(
      o, f.exposures_truth, footprint, seen_by, random, &f.points_truth, &f.points_file);
  for (const auto& p : f.points_truth)
    for (size_t i = 0; i < f.exposures_truth.size(); ++i)
      AddHeadObservations(f, i, p.id, HeadsSeeing(f, i, *p.xyz_m), random);
  AddStitchingTies(f, random);
  return f;
}

calib::Rig ScaleRigFormats(const calib::Rig& rig, double scale) {
  if (!(scale > 0 && scale <= 1))
    throw ConfigError("--format-scale must be within (0, 1] (got " + std::to_string(scale) + ")");
  calib::Rig out = rig;
  if (scale == 1.0) return out;
  const auto scaled = [scale](int px) {
    return std::max(16, static_cast<int>(std::lround(px * scale)));
  };
  for (calib::RigHead& head : out.heads) {
    head.camera.width_px = scaled(head.camera.width_px);
    head.camera.height_px = scaled(head.camera.height_px);
    head.camera.pixel_size_mm /= scale;
  }
  calib::Camera& v = out.virtual_camera.camera;
  v.width_px = scaled(v.width_px);
  v.height_px = scaled(v.height_px);
  v.pixel_size_mm /= scale;
  return out;
}

void RigImageOptions::Validate() const {
  if (texture_path.empty())
    throw ConfigError("--texture: the photograph of the scene is required with --render-images");
  if (!(texture_gsd_m >= 0)) throw ConfigError("--texture-gsd-m must be >= 0");
  if (!(grey_noise_dn >= 0)) throw ConfigError("--grey-noise-dn must be >= 0");
}

TexturedGround MakeRigGroundTexture(const SimulatedRigFlight& f, const RigImageOptions& options) {
  options.Validate();
  TexturedGround ground;
  ReadGroundTexture(options.texture_path, &ground);
  const calib::Camera& v = f.nominal.virtual_camera.camera;
  ground.gsd_m = options.texture_gsd_m > 0
                     ? options.texture_gsd_m
                     : 0.5 * v.pixel_size_mm * f.options.flight.flying_height_m / v.c_mm();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Exposure& e : f.exposures_truth) centre += e.center_m.head<2>();
  centre /= static_cast<double>(f.exposures_truth.size());
  ground.x_c = centre.x();
  ground.y_c = centre.y();
  return ground;
}

stitch::GrayImage RenderRigHeadImage(const SimulatedRigFlight& f,
                                     const TexturedGround& ground,
                                     const RigImageOptions& options,
                                     int exposure,
                                     int head) {
  const size_t heads = f.truth.heads.size();
  AEROCAL_CHECK(exposure >= 0 && exposure < static_cast<int>(f.exposures_truth.size()) &&
                head >= 0 && head < static_cast<int>(heads))
      << exposure << " " << head;
  const calib::RigHead& h = f.truth.heads[head];
  const Exposure& e = f.exposures_truth[exposure];
  const RigExposureTruth& t = f.rig_exposures[exposure * heads + head];
  const Eigen::Vector3d velocity = e.velocity_mps.value_or(Eigen::Vector3d::Zero());
  double rotation[9], center[3];
  calib::HeadPose(e.opk_rad.data(),
                  e.center_m.data(),
                  h.mount_rad.data(),
                  h.lever_arm_m.data(),
                  t.increment_rad.data(),
                  &t.dt_s,
                  velocity.data(),
                  rotation,
                  center);
  const Eigen::Vector3d opk = calib::OpkFromRotation(
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation));
  const Eigen::Vector3d origin(center[0], center[1], center[2]);
  std::mt19937_64 rng(options.seed * 7919 + 13 + 1009 * static_cast<std::uint64_t>(exposure) +
                      static_cast<std::uint64_t>(head));
  std::normal_distribution<double> noise(0.0, 1.0);
  // The ground point of the ray through head pixel (c, r): 40 halvings of the terrain's height
  // range, far below 1e-6 m.
  const auto ground_of = [&](double c, double r) {
    const ImageRay ray = RayFromPixel(h.camera, opk, origin, Eigen::Vector2d(c, r));
    Eigen::Vector3d g;
    if (!TerrainPointOfRay(f.options.flight, ray.center_m, ray.direction, &g, 40))
      throw Error("image mode: a ray of head " + h.id + " in " + e.image + " does not point down");
    return Eigen::Vector2d(g.x(), g.y());
  };
  const int cols = h.camera.width_px, rows = h.camera.height_px;
  stitch::GrayImage image(rows, cols);
  if (options.point_sampling) {
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const Eigen::Vector2d g = ground_of(c, r);
        image(r, c) =
            static_cast<float>(ground.At(g.x(), g.y()) + options.grey_noise_dn * noise(rng));
      }
    return image;
  }
  // Area integration: pixel (c, r) covers [c - 1/2, c + 1/2] x [r - 1/2, r + 1/2]; the ground
  // points of its four corners are exact ray intersections, the points inside bilinear in them
  // (the mapping is smooth over one pixel); n x n samples at the centres of n x n equal
  // sub-squares, n = ceil(the footprint's longer diagonal / texel) within [2, kMaxSamples], so
  // that the samples are at most a texel apart (for footprints up to 8 texels across; the default
  // texel, half the nadir GSD, gives about 3 at nadir) and the bilinear texture is integrated
  // over the footprint (a box filter: the sensor's pixel area).
  constexpr int kMaxSamples = 8;
  std::vector<Eigen::Vector2d> top(cols + 1), bottom(cols + 1);
  for (int c = 0; c <= cols; ++c) top[c] = ground_of(c - 0.5, -0.5);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c <= cols; ++c) bottom[c] = ground_of(c - 0.5, r + 0.5);
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d& g00 = top[c];
      const Eigen::Vector2d& g10 = top[c + 1];
      const Eigen::Vector2d& g01 = bottom[c];
      const Eigen::Vector2d& g11 = bottom[c + 1];
      const double diagonal_m = std::max((g11 - g00).norm(), (g10 - g01).norm());
      const int n =
          std::clamp(static_cast<int>(std::ceil(diagonal_m / ground.gsd_m)), 2, kMaxSamples);
      double sum = 0.0;
      for (int j = 0; j < n; ++j) {
        const double v = (j + 0.5) / n;
        const Eigen::Vector2d left = (1.0 - v) * g00 + v * g01, right = (1.0 - v) * g10 + v * g11;
        for (int i = 0; i < n; ++i) {
          const double u = (i + 0.5) / n;
          const Eigen::Vector2d g = (1.0 - u) * left + u * right;
          sum += ground.At(g.x(), g.y());
        }
      }
      image(r, c) = static_cast<float>(sum / (n * n) + options.grey_noise_dn * noise(rng));
    }
    std::swap(top, bottom);
  }
  return image;
}

std::string RigHeadImagePath(const std::string& folder,
                             const std::string& image,
                             const std::string& head) {
  return folder + "/images/" + image + "_" + head + ".tif";
}

double WriteRigHeadImages(const SimulatedRigFlight& f,
                          const RigImageOptions& options,
                          const std::string& folder) {
  const TexturedGround ground = MakeRigGroundTexture(f, options);
  std::filesystem::create_directories(folder + "/images");
  for (size_t i = 0; i < f.exposures_truth.size(); ++i)
    for (size_t k = 0; k < f.truth.heads.size(); ++k)
      stitch::WriteGrayImage(
          RigHeadImagePath(folder, f.exposures_truth[i].image, f.truth.heads[k].id),
          RenderRigHeadImage(f, ground, options, static_cast<int>(i), static_cast<int>(k)));
  return ground.gsd_m;
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
          << StringPrintf("%.10f,%.10f,%.10f,%.6f",
                          t.increment_rad.x() / kDegToRad,
                          t.increment_rad.y() / kDegToRad,
                          t.increment_rad.z() / kDegToRad,
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
