#include "triangulation/simulation/flight_simulator.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/block/block_io.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kMarginPx = 20.0;  // points are measured at least this far inside the format
using Model = calib::Camera::Model;

struct Visible {
  int image;
  Eigen::Vector2d pixel;
};

// Which exposures can see a point, without projecting it into every exposure of the block (that
// made the simulation quadratic in the block size: 10,000 exposures did not finish in 99 min).
// A uniform grid over the ground holds each exposure in the cells its ground disc touches. The
// disc bounds where a point at or above `min_height_m` can project inside the format: the ray to
// such a point lies within theta of the exposure's axis (tan theta: the widest ideal ray of the
// format, sampled, +10 %), the axis within tau of the nadir, so the point lies at most
// (Z0 - min_height_m) tan(theta + tau) from the centre horizontally. Candidates come out in
// increasing exposure index: the exact test (VisibleIn) on them gives the same list, in the same
// order, as on every exposure, so the files of a seed do not change. Where no such bound holds (a
// cone near the horizon, a centre at or below `min_height_m`, a point below it) every exposure
// is a candidate.
class ExposureIndex {
 public:
  ExposureIndex(const calib::Camera& camera,
                const std::vector<Exposure>& exposures,
                double min_height_m)
      : min_height_m_(min_height_m), all_(exposures.size()) {
    for (size_t i = 0; i < exposures.size(); ++i) all_[i] = static_cast<int>(i);
    const double tan_format = WidestRayTangent(camera);
    if (!(tan_format > 0) || exposures.empty()) return;
    const double theta = std::atan(1.1 * tan_format);
    radius_m_.resize(exposures.size());
    double x_min = 1e300, x_max = -1e300, y_min = 1e300, y_max = -1e300, r_max = 0.0;
    for (size_t i = 0; i < exposures.size(); ++i) {
      const Exposure& e = exposures[i];
      const double cos_tau = std::clamp(calib::RotationFromOpk(e.opk_rad)(2, 2), -1.0, 1.0);
      const double cone_rad = theta + std::acos(cos_tau);
      const double depth_m = e.center_m.z() - min_height_m;
      if (!(cone_rad < 80.0 * kDegToRad) || !(depth_m > 0) || !e.center_m.allFinite()) return;
      radius_m_[i] = depth_m * std::tan(cone_rad);
      x_min = std::min(x_min, e.center_m.x() - radius_m_[i]);
      x_max = std::max(x_max, e.center_m.x() + radius_m_[i]);
      y_min = std::min(y_min, e.center_m.y() - radius_m_[i]);
      y_max = std::max(y_max, e.center_m.y() + radius_m_[i]);
      r_max = std::max(r_max, radius_m_[i]);
    }
    // Cells of the largest radius; coarser where that would make more than 16 cells per exposure.
    cell_m_ = std::max(r_max, 1e-3);
    const double max_cells = 16.0 * exposures.size() + 1024.0;
    while ((x_max - x_min) / cell_m_ * ((y_max - y_min) / cell_m_) > max_cells) cell_m_ *= 2.0;
    x0_m_ = x_min;
    y0_m_ = y_min;
    nx_ = static_cast<int>((x_max - x_min) / cell_m_) + 1;
    ny_ = static_cast<int>((y_max - y_min) / cell_m_) + 1;
    cells_.resize(static_cast<size_t>(nx_) * ny_);
    for (size_t i = 0; i < exposures.size(); ++i) {
      const Eigen::Vector3d& c = exposures[i].center_m;
      const double r = radius_m_[i];
      for (int j = Cell(c.y() - r, y0_m_, ny_); j <= Cell(c.y() + r, y0_m_, ny_); ++j)
        for (int k = Cell(c.x() - r, x0_m_, nx_); k <= Cell(c.x() + r, x0_m_, nx_); ++k)
          cells_[static_cast<size_t>(j) * nx_ + k].push_back(static_cast<int>(i));
      centers_m_.push_back(c.head<2>());
    }
    indexed_ = true;
  }

  /// The exposures that may see `point`, in increasing index.
  std::vector<int> Candidates(const Eigen::Vector3d& point) const {
    if (!indexed_ || !(point.z() >= min_height_m_) || !point.allFinite()) return all_;
    std::vector<int> out;
    const double fx = (point.x() - x0_m_) / cell_m_, fy = (point.y() - y0_m_) / cell_m_;
    if (!(fx >= 0 && fy >= 0 && fx < nx_ && fy < ny_)) return out;  // outside every disc
    for (int i : cells_[static_cast<size_t>(fy) * nx_ + static_cast<size_t>(fx)])
      if ((point.head<2>() - centers_m_[i]).norm() <= radius_m_[i]) out.push_back(i);
    return out;
  }

 private:
  // tan of the widest ray of the format: max |ideal| / c over 65 x 65 pixels spanning it (0 when
  // the model's inversion fails somewhere: no index then).
  static double WidestRayTangent(const calib::Camera& camera) {
    constexpr int kSteps = 64;
    double widest_mm = 0.0;
    for (int a = 0; a <= kSteps; ++a) {
      for (int b = 0; b <= kSteps; ++b) {
        const Eigen::Vector2d pixel(a * (camera.width_px - 1.0) / kSteps,
                                    b * (camera.height_px - 1.0) / kSteps);
        Eigen::Vector2d ideal_mm;
        if (!camera.IdealFromPixel(pixel, &ideal_mm) || !ideal_mm.allFinite()) return 0.0;
        widest_mm = std::max(widest_mm, ideal_mm.norm());
      }
    }
    return widest_mm / camera.c_mm();
  }
  int Cell(double v_m, double v0_m, int n) const {
    return std::clamp(static_cast<int>((v_m - v0_m) / cell_m_), 0, n - 1);
  }

  double min_height_m_;
  std::vector<int> all_;
  bool indexed_ = false;
  std::vector<double> radius_m_;
  std::vector<Eigen::Vector2d> centers_m_;
  double cell_m_ = 1.0, x0_m_ = 0.0, y0_m_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<int>> cells_;  // exposure indices, increasing, row-major over (y, x)
};

// The candidate images (increasing index) in which `point` projects inside the format (margin
// in px).
std::vector<Visible> VisibleIn(const calib::Camera& camera,
                               const std::vector<Exposure>& exposures,
                               const std::vector<int>& candidates,
                               const Eigen::Vector3d& point,
                               double margin_px) {
  std::vector<Visible> out;
  for (const int i : candidates) {
    Eigen::Vector2d px;
    if (!camera.ProjectToPixel(exposures[i].opk_rad, exposures[i].center_m, point, &px)) continue;
    if (px.x() < margin_px || px.y() < margin_px || px.x() > camera.width_px - 1 - margin_px ||
        px.y() > camera.height_px - 1 - margin_px)
      continue;
    out.push_back({i, px});
  }
  return out;
}

}  // namespace

namespace internal {

std::vector<Exposure> PlanStrips(const FlightSimulationOptions& o,
                                 const Eigen::Vector2d& footprint_m,
                                 const std::string& camera,
                                 SimulationRandom& random) {
  auto& normal = random.normal;
  auto& rng = random.rng;
  const double base = (1.0 - o.forward_overlap) * footprint_m.x();
  const double spacing = (1.0 - o.side_overlap) * footprint_m.y();
  const double mean_terrain = o.terrain_base_m + 0.5 * o.terrain_relief_m;
  std::vector<Exposure> truth;
  int remaining = o.exposures;
  for (int s = 0; s < o.strips; ++s) {
    const int n = (remaining + (o.strips - s) - 1) / (o.strips - s);
    remaining -= n;
    for (int k = 0; k < n; ++k) {
      Exposure e;
      char id[32];
      std::snprintf(id, sizeof(id), "%04d", static_cast<int>(truth.size()) + 1);
      e.image = id;
      e.camera = camera;
      const int along = s % 2 == 0 ? k : n - 1 - k;
      e.center_m = {(along - 0.5 * (n - 1)) * base,
                    (s - 0.5 * (o.strips - 1)) * spacing,
                    mean_terrain + o.flying_height_m};
      e.opk_rad = {o.attitude_sigma_deg * kDegToRad * normal(rng),
                   o.attitude_sigma_deg * kDegToRad * normal(rng),
                   (s % 2 == 0 ? 0.0 : M_PI) + o.attitude_sigma_deg * kDegToRad * normal(rng)};
      truth.push_back(e);
    }
  }
  return truth;
}

std::vector<Exposure> ExposuresAsMeasured(const FlightSimulationOptions& o,
                                          const std::vector<Exposure>& truth,
                                          SimulationRandom& random) {
  auto& normal = random.normal;
  auto& rng = random.rng;
  std::vector<Exposure> measured;
  for (const auto& t : truth) {
    Exposure e = t;
    if (o.speed_mps > 0)  // along the strip, in its direction of flight (kappa)
      e.velocity_mps = Eigen::Vector3d(
          o.speed_mps * std::cos(t.opk_rad.z()), o.speed_mps * std::sin(t.opk_rad.z()), 0.0);
    const Eigen::Matrix3d r = calib::RotationFromOpk(t.opk_rad);
    if (o.gnss_sigma_m > 0) {
      e.center_m += r * o.lever_arm_m +
                    e.velocity_mps.value_or(Eigen::Vector3d::Zero()) * o.gnss_time_offset_s;
      e.center_m += o.gnss_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
      e.center_sigma_m = Eigen::Vector3d::Constant(o.gnss_sigma_m);
    } else {
      e.center_m +=
          o.start_position_error_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    }
    if (o.imu_sigma_deg > 0) {
      if (!o.boresight_rad.isZero())
        e.opk_rad = calib::OpkFromRotation(r * calib::RotationFromOpk(o.boresight_rad).transpose());
      e.opk_rad +=
          o.imu_sigma_deg * kDegToRad * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
      e.opk_sigma_rad = Eigen::Vector3d::Constant(o.imu_sigma_deg * kDegToRad);
    } else {
      e.opk_rad += o.start_angle_error_deg * kDegToRad *
                   Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    }
    measured.push_back(e);
  }
  return measured;
}

void PlacePoints(const FlightSimulationOptions& o,
                 const std::vector<Exposure>& exposures,
                 const Eigen::Vector2d& footprint_m,
                 const std::function<int(const Eigen::Vector3d&)>& seen_by,
                 SimulationRandom& random,
                 std::vector<GroundPoint>* points_truth,
                 std::vector<GroundPoint>* points_file) {
  auto& normal = random.normal;
  auto& uniform = random.uniform;
  auto& rng = random.rng;
  const double footprint_x = footprint_m.x(), footprint_y = footprint_m.y();
  // Ground points: surveyed (control at corners + centre, then check) and tie points, each seen
  // in at least two images.
  double x_min = 1e300, x_max = -1e300, y_min = 1e300, y_max = -1e300;
  for (const auto& e : exposures) {
    x_min = std::min(x_min, e.center_m.x());
    x_max = std::max(x_max, e.center_m.x());
    y_min = std::min(y_min, e.center_m.y());
    y_max = std::max(y_max, e.center_m.y());
  }
  x_min -= 0.45 * footprint_x;
  x_max += 0.45 * footprint_x;
  y_min -= 0.45 * footprint_y;
  y_max += 0.45 * footprint_y;
  auto ground = [&](double x, double y) {
    return Eigen::Vector3d(x, y, SimulatedTerrainHeight(o, x, y));
  };
  auto add_point = [&](const std::string& id, const Eigen::Vector3d& p, PointRole role) {
    GroundPoint g;
    g.id = id;
    g.xyz_m = p;
    g.role = role;
    g.sigma_m = Eigen::Vector3d::Constant(o.survey_sigma_m);
    points_truth->push_back(g);
  };
  // Control: walk from each target towards the block centre until >= 3 images see it.
  const Eigen::Vector2d centre(0.5 * (x_min + x_max), 0.5 * (y_min + y_max));
  std::vector<Eigen::Vector2d> targets = {
      {x_min, y_min}, {x_max, y_min}, {x_min, y_max}, {x_max, y_max}, centre};
  targets.resize(std::min<size_t>(targets.size(), std::max(0, o.control_points)));
  for (int extra = static_cast<int>(targets.size()); extra < o.control_points; ++extra)
    targets.push_back(
        {x_min + uniform(rng) * (x_max - x_min), y_min + uniform(rng) * (y_max - y_min)});
  int control_id = 0;
  // (The centre itself may lie in a two-fold overlap: look around it along the strip as well.)
  const double step_x = 0.05 * footprint_x;
  for (const auto& target : targets) {
    bool placed = false;
    for (double t = 0.0; t <= 1.0 && !placed; t += 0.01) {
      for (int k = 0; k <= 20 && !placed; ++k) {
        const double dx = (k % 2 == 0 ? 1 : -1) * ((k + 1) / 2) * step_x;
        const Eigen::Vector2d xy = target + t * (centre - target) + Eigen::Vector2d(dx, 0.0);
        const Eigen::Vector3d p = ground(xy.x(), xy.y());
        if (seen_by(p) >= 3) {
          add_point("C" + std::to_string(++control_id), p, PointRole::kControl);
          placed = true;
        }
      }
    }
  }
  auto sample = [&](int count, const std::string& prefix, PointRole role) {
    int made = 0;
    for (int attempt = 0; made < count && attempt < 200 * count + 1000; ++attempt) {
      const Eigen::Vector3d p =
          ground(x_min + uniform(rng) * (x_max - x_min), y_min + uniform(rng) * (y_max - y_min));
      if (seen_by(p) < 2) continue;
      add_point(prefix + std::to_string(++made), p, role);
    }
  };
  sample(o.ground_points - control_id, "K", PointRole::kCheck);
  sample(o.tie_points, "T", PointRole::kTie);

  for (const auto& t : *points_truth) {
    GroundPoint g = t;
    if (g.role == PointRole::kTie) {
      g.xyz_m.reset();
    } else {
      *g.xyz_m += o.survey_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    }
    points_file->push_back(g);
  }
}

}  // namespace internal

stitch::GridLayoutOptions FlightSimulationOptions::DefaultLayout() {
  stitch::GridLayoutOptions layout;
  layout.name = "aerocal simulated 2x3-CCD camera";
  layout.rows = 3;
  layout.cols = 2;
  layout.virtual_width_px = 14000;
  layout.virtual_height_px = 12000;
  layout.overlap_px = 200;
  layout.pixel_size_mm = 0.009;
  layout.c_mm = 170.0;
  layout.model = calib::MappingModel::kAffine;
  layout.base_ids = {"III", "IV"};
  layout.reference_placement = stitch::ReferencePlacement::kBaseCorners;
  return layout;
}

stitch::MisplacementOptions FlightSimulationOptions::DefaultMisplacement() {
  stitch::MisplacementOptions m;
  m.shift_sigma_px = 3.0;
  m.rotation_sigma_rad = 5e-5;
  m.scale_sigma = 5e-5;
  m.shear = 2e-5;
  return m;
}

calib::InteriorParams FlightSimulationOptions::DefaultInteriorCorrection() {
  calib::InteriorParams d{};
  d[Model::kC] = 0.038;     // mm
  d[Model::kX0] = -0.0024;  // mm
  d[Model::kY0] = 0.0015;   // mm
  d[Model::kK1] = 3.0e-8;   // 2.3 um at r = 50 mm, 15 um (1.7 px) at the corner (r = 83 mm)
  d[Model::kK2] = -2.0e-12;
  d[Model::kK3] = 1.0e-16;
  d[Model::kP1] = 2.0e-7;
  d[Model::kP2] = -1.5e-7;
  d[Model::kB1] = 1.0e-5;
  d[Model::kB2] = -8.0e-6;
  return d;
}

double SimulatedTerrainHeight(const FlightSimulationOptions& o, double x, double y) {
  const double shape =
      0.5 + 0.32 * std::sin(2 * M_PI * x / 9000.0 + 0.3) * std::cos(2 * M_PI * y / 7000.0) +
      0.16 * std::sin(2 * M_PI * (x / 3100.0 + y / 4100.0));
  return o.terrain_base_m + o.terrain_relief_m * std::clamp(shape, 0.0, 1.0);
}

SimulatedFlight SimulateFlight(const FlightSimulationOptions& o) {
  if (o.exposures < 2 || o.strips < 1 || o.exposures < o.strips)
    throw ConfigError("a flight needs at least 2 exposures and one strip per exposure row");
  // Sizes that are products of options, bounded before anything is made (issue 37 class 7): every
  // stitching tie of every exposure is kept (~0.5 kB with its observations), and every ground
  // point is projected into every exposure.
  const double ties = double(o.exposures) * o.stitching.ties_per_frame;
  if (ties > kMaxSimulatedStitchTies)
    throw ConfigError("--exposures x --stitch-ties: " + FormatNumber(ties) +
                      " stitching ties are more than " + FormatNumber(kMaxSimulatedStitchTies) +
                      " (fewer --stitch-ties, default 900 a frame)");
  const double pairs = double(o.exposures) * (double(o.ground_points) + o.tie_points);
  if (pairs > kMaxSimulatedPointExposurePairs)
    throw ConfigError("--exposures x (--surveyed-points + --tie-points): " + FormatNumber(pairs) +
                      " point-exposure pairs are more than " +
                      FormatNumber(kMaxSimulatedPointExposurePairs));
  internal::SimulationRandom random(o.seed);
  std::mt19937_64& rng = random.rng;
  std::normal_distribution<double>& normal = random.normal;

  SimulatedFlight f;
  f.options = o;
  f.nominal = stitch::MakeGridCamera(o.layout);
  f.truth = stitch::MakeMisplacedCamera(f.nominal, o.layout.base_ids, o.misplacement, rng);
  for (int i = 0; i < Model::kNumParams; ++i) f.truth.interior[i] += o.interior_correction[i];
  f.truth.name = f.nominal.name + " (truth)";

  const double scale = o.flying_height_m / (o.layout.c_mm * 1e-3);
  const Eigen::Vector2d footprint(f.nominal.width_px * f.nominal.pixel_size_mm * 1e-3 * scale,
                                  f.nominal.height_px * f.nominal.pixel_size_mm * 1e-3 * scale);
  f.exposures_truth = internal::PlanStrips(o, footprint, "cam1", random);
  f.exposures_file = internal::ExposuresAsMeasured(o, f.exposures_truth, random);
  const ExposureIndex index(f.truth, f.exposures_truth, o.terrain_base_m);  // terrain minimum
  const auto visible = [&](const Eigen::Vector3d& p) {
    return VisibleIn(f.truth, f.exposures_truth, index.Candidates(p), p, kMarginPx);
  };
  const auto seen_by = [&](const Eigen::Vector3d& p) {
    return static_cast<int>(visible(p).size());
  };
  internal::PlacePoints(
      o, f.exposures_truth, footprint, seen_by, random, &f.points_truth, &f.points_file);

  // Image observations: virtual-image pixels and the same points in raw sub-image pixels.
  for (const auto& p : f.points_truth) {
    for (const auto& v : visible(*p.xyz_m)) {
      ImageObservation obs;
      obs.image = f.exposures_truth[v.image].image;
      obs.point = p.id;
      obs.sigma_px = o.image_sigma_px;
      obs.pixel = v.pixel + o.image_noise_px * Eigen::Vector2d(normal(rng), normal(rng));
      f.observations.push_back(obs);
      for (const auto& s : f.truth.subimages) {
        const Eigen::Vector2d uv = s.SubFromVirtual(v.pixel);
        if (!s.Contains(uv, -2.0)) continue;
        ImageObservation sub = obs;
        sub.subimage = s.id;
        sub.pixel = uv + o.image_noise_px * Eigen::Vector2d(normal(rng), normal(rng));
        f.subimage_observations.push_back(sub);
      }
    }
  }
  // Per-exposure stitching measurements (frame = image id).
  for (const auto& e : f.exposures_truth) {
    auto rows = stitch::SimulateFrame(f.truth, e.image, o.stitching, rng);
    f.stitching.insert(f.stitching.end(), rows.begin(), rows.end());
  }
  return f;
}

void WriteSimulatedFlight(const SimulatedFlight& f, const std::string& folder) {
  const auto path = [&](const std::string& name) { return folder + "/" + name; };
  calib::WriteCamera(path("camera_nominal.yaml"), f.nominal);
  calib::WriteCamera(path("camera_truth.yaml"), f.truth);
  WriteExposures(path("exposures.csv"), f.exposures_file);
  WriteObservations(path("observations.csv"), f.observations);
  WriteObservations(path("observations_subimage.csv"), f.subimage_observations);
  WritePoints(path("points.csv"), f.points_file);
  stitch::WriteStitchObservations(path("stitch_obs.csv"), f.stitching);
  WriteExposures(path("truth/exposures.csv"), f.exposures_truth);
  WritePoints(path("truth/points.csv"), f.points_truth);
  const std::string project = "# Simulated flight (aerocal simulate --seed " +
                              std::to_string(f.options.seed) +
                              ")\n"
                              "cameras: {cam1: camera_nominal.yaml}\n"
                              "exposures: exposures.csv\n"
                              "points: points.csv\n"
                              "stitching: stitch_obs.csv\n"
                              "frame: {projected: \"simulated local frame\"}\n";
  WriteFileAtomically(path("project.yaml"), project + "observations: observations.csv\n");
  WriteFileAtomically(path("project_subimage.yaml"),
                      project + "observations: observations_subimage.csv\n");
}

}  // namespace aerocal::triangulation
