#include "triangulation/simulation/test_field_simulator.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "triangulation/block/block_io.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <random>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;
constexpr double kPi = 3.14159265358979323846;

// A 24 mm lens on a 4000 x 3000 px sensor of 6 um (24 x 18 mm): an industrial / metric camera of a
// test-field calibration, with the distortion of a good wide-angle lens (about 12 px at the format
// corner from K1, 1 px from P1, P2).
calib::Camera TruthCamera() {
  calib::Camera c;
  c.name = "test-field camera";
  c.pixel_size_mm = 0.006;
  c.width_px = 4000;
  c.height_px = 3000;
  c.interior = {24.052, 0.021, -0.014, -2.1e-5, 4.0e-8, 0.0, 1.2e-6, -0.9e-6, 0.0, 0.0};
  return c;
}

// object_from_image of a camera at `center` looking at `target` with roll `roll_rad` about its
// axis: image z = -viewing direction (the camera looks along -z, CONVENTIONS.md), image y up.
Eigen::Matrix3d LookAt(const Eigen::Vector3d& center,
                       const Eigen::Vector3d& target,
                       double roll_rad) {
  const Eigen::Vector3d z = (center - target).normalized();
  Eigen::Vector3d y0 = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z) * z;
  y0.normalize();
  const Eigen::Vector3d x0 = y0.cross(z);
  const Eigen::Vector3d x = std::cos(roll_rad) * x0 + std::sin(roll_rad) * y0;
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  return r;
}

}  // namespace

void TestFieldOptions::Validate() const {
  const auto require = [](bool ok, const std::string& what) {
    if (!ok) throw ConfigError(what);
  };
  require(width_m > 0 && height_m > 0, "test field: width_m and height_m must be > 0");
  require(target_spacing_m > 0 && width_m / target_spacing_m <= 200 &&
              height_m / target_spacing_m <= 200,
          "test field: target_spacing_m must be > 0 and give at most 200 targets per side");
  require(groups >= 1 && groups <= 26, "test field: groups must be 1..26");
  require(images_per_group >= 4 && images_per_group <= 1000,
          "test field: images_per_group must be 4..1000");
  require(distance_m > 0, "test field: distance_m must be > 0");
  require(survey_sigma_m > 0, "test field: survey_sigma_m must be > 0");
  require(image_noise_px >= 0 && image_sigma_px > 0,
          "test field: image noise >= 0, image sigma > 0 px");
  require(check_every >= 0, "test field: check_every must be >= 0");
  require(changed_group < groups, "test field: changed_group must be below groups");
}

SimulatedTestField SimulateTestField(const TestFieldOptions& o) {
  o.Validate();
  SimulatedTestField f;
  f.options = o;
  f.truth = TruthCamera();
  f.nominal = f.truth;
  f.nominal.name = "test-field camera (nominal)";
  f.nominal.interior = {};
  f.nominal.interior[Model::kC] = 24.0;
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);

  // Targets: the wall grid; without `planar`, balcony fronts (0.8 m in front) on every third
  // row and pillars (1.6 m in front) on every fourth column.
  const int nx = static_cast<int>(std::floor(o.width_m / o.target_spacing_m)) + 1;
  const int nz = static_cast<int>(std::floor(o.height_m / o.target_spacing_m)) + 1;
  int number = 0;
  const auto add_target = [&](const Eigen::Vector3d& xyz) {
    GroundPoint t;
    char id[16];
    std::snprintf(id, sizeof(id), "T%04d", ++number);
    t.id = id;
    t.xyz_m = xyz;
    t.sigma_m = Eigen::Vector3d::Constant(o.survey_sigma_m);
    t.role =
        o.check_every > 0 && number % o.check_every == 0 ? PointRole::kCheck : PointRole::kControl;
    f.points_truth.push_back(t);
    GroundPoint file = t;
    file.xyz_m = xyz + o.survey_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    f.points_file.push_back(file);
  };
  for (int k = 0; k < nz; ++k)
    for (int i = 0; i < nx; ++i) {
      const double x = -0.5 * o.width_m + i * o.target_spacing_m, z = k * o.target_spacing_m;
      double y = 0.0;
      if (!o.planar && k % 3 == 1) y = -0.8;
      if (!o.planar && i % 4 == 2) y = -1.6;
      add_target({x, y, z});
    }

  // Stations: per group the same network with its own jitter: positions across the facade at
  // three heights, rolls 0, 90, 180, 270 deg in turn.
  const Eigen::Vector3d centre(0.0, 0.0, 0.5 * o.height_m);
  const int n = o.images_per_group;
  for (int g = 0; g < o.groups; ++g) {
    calib::Camera camera = f.truth;
    if (g == o.changed_group)
      for (int k = 0; k < Model::kNumParams; ++k) camera.interior[k] += o.group_camera_change[k];
    const std::string group(1, static_cast<char>('A' + g));
    for (int s = 0; s < n; ++s) {
      Exposure e;
      char id[32];
      std::snprintf(id, sizeof(id), "%s%03d", group.c_str(), s + 1);
      e.image = id;
      e.camera = "cam1";
      const double across = n > 1 ? -0.5 + static_cast<double>(s) / (n - 1) : 0.0;
      e.center_m = Eigen::Vector3d(0.9 * o.width_m * across + 0.5 * uniform(rng),
                                   -o.distance_m * (1.0 + 0.1 * uniform(rng)),
                                   o.height_m * (0.1 + 0.4 * (s % 3)) + 0.5 * uniform(rng));
      const Eigen::Vector3d target = centre + Eigen::Vector3d(uniform(rng), 0.0, uniform(rng));
      const double roll = 0.5 * kPi * (s % 4) + 0.05 * uniform(rng);
      e.opk_rad = calib::OpkFromRotation(LookAt(e.center_m, target, roll));
      f.exposures_truth.push_back(e);
      f.group_of_image[e.image] = group;
      for (const GroundPoint& t : f.points_truth) {
        Eigen::Vector2d pixel;
        if (!camera.ProjectToPixel(e.opk_rad, e.center_m, *t.xyz_m, &pixel)) continue;
        if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > camera.width_px - 1 ||
            pixel.y() > camera.height_px - 1)
          continue;
        ImageObservation obs;
        obs.image = e.image;
        obs.point = t.id;
        obs.pixel = pixel + o.image_noise_px * Eigen::Vector2d(normal(rng), normal(rng));
        obs.sigma_px = o.image_sigma_px;
        f.observations.push_back(obs);
      }
    }
  }
  return f;
}

Project TestFieldProject(const SimulatedTestField& f) {
  Project p;
  p.cameras["cam1"] = f.nominal;
  p.points = f.points_file;
  p.observations = f.observations;
  return p;
}

void WriteSimulatedTestField(const SimulatedTestField& f, const std::string& folder) {
  const auto path = [&](const std::string& name) { return folder + "/" + name; };
  calib::WriteCamera(path("camera_nominal.yaml"), f.nominal);
  calib::WriteCamera(path("camera_truth.yaml"), f.truth);
  WriteObservations(path("observations.csv"), f.observations);
  WritePoints(path("points.csv"), f.points_file);
  std::string groups = "image,group\n";
  for (const auto& [image, group] : f.group_of_image) groups += image + "," + group + "\n";
  WriteFileAtomically(path("groups.csv"), groups);
  WriteExposures(path("truth/exposures.csv"), f.exposures_truth);
  WritePoints(path("truth/points.csv"), f.points_truth);
}

}  // namespace aerocal::triangulation
