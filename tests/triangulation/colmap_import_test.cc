// COLMAP text model -> block: pixel (+0.5) and camera-frame conventions, intrinsics fitted to the
// 10-parameter model; round trip through aerocal's projection.
#include "triangulation/import/colmap_import.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

namespace aerocal::triangulation {
namespace {

struct Scene {
  std::string model;
  std::vector<double> params;
};

// Writes a COLMAP model of 6 images looking at 200 points from ~10 m, returns the point truth.
std::vector<Eigen::Vector3d> WriteModel(const std::string& dir, const Scene& scene) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(4 * u(rng), 3 * u(rng), 0.5 * u(rng));
  std::ofstream cameras(dir + "/cameras.txt"), images(dir + "/images.txt"),
      pts(dir + "/points3D.txt");
  cameras << "# Camera list\n1 " << scene.model << " 3000 2000";
  for (double p : scene.params) cameras << " " << p;
  cameras << "\n";
  images << "# Image list with two lines of data per image\n";
  for (int k = 0; k < 6; ++k) {
    // Camera above the scene looking down (COLMAP z forward = world -Z), tilted a little.
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    const Eigen::Vector3d center(1.0 * k - 2.5, 0.3 * k, 10.0);
    const Eigen::Vector3d t = -r * center;
    const Eigen::Quaterniond q(r);
    images << k + 1 << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x()
           << " " << t.y() << " " << t.z() << " 1 img" << k + 1 << ".jpg\n";
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d c = r * points[i] + t;
      const Eigen::Vector2d px = ColmapProject(scene.model, scene.params, c);
      if (px.x() < 0 || px.y() < 0 || px.x() > 3000 || px.y() > 2000) continue;
      images << px.x() << " " << px.y() << " " << i + 1 << " ";
    }
    images << "\n";
  }
  for (size_t i = 0; i < points.size(); ++i)
    pts << i + 1 << " " << points[i].x() << " " << points[i].y() << " " << points[i].z()
        << " 0 0 0 0.1\n";
  return points;
}

class ColmapImport : public ::testing::TestWithParam<Scene> {};

TEST_P(ColmapImport, ImportedCameraReprojectsColmapPixels) {
  testing::TempDir dir("aerocal_colmap");
  const auto truth = WriteModel(dir.path(), GetParam());
  ColmapImportOptions options;
  options.folder = dir.path();
  const auto report = ImportColmapModel(options);
  const Project& p = report.project;
  ASSERT_EQ(p.exposures.size(), 6u);
  ASSERT_GT(p.observations.size(), 600u);
  std::printf("%s\n", report.notes.front().c_str());
  double max_error = 0.0;
  for (const auto& o : p.observations) {
    const Exposure* e = p.FindExposure(o.image);
    Eigen::Vector2d px;
    ASSERT_TRUE(p.cameras.at("1").ProjectToPixel(
        e->opk_rad, e->center_m, truth[std::stoi(o.point) - 1], &px));
    max_error = std::max(max_error, (px - o.pixel).norm());
  }
  // The forward COLMAP distortion is fitted by the correction model: a few hundredths of a pixel.
  EXPECT_LT(max_error, 0.05) << GetParam().model;
  // The imported block adjusts to (nearly) zero residuals in a free-network datum.
  AdjustOptions adjust;
  adjust.data_snooping = false;
  const AdjustmentResult r = Adjust(p, adjust);
  ASSERT_TRUE(r.converged());
  EXPECT_LT(r.sigma0_px, 0.02);
}

INSTANTIATE_TEST_SUITE_P(
    Models,
    ColmapImport,
    ::testing::Values(Scene{"PINHOLE", {2400, 2410, 1510, 990}},
                      Scene{"SIMPLE_RADIAL", {2400, 1500, 1000, -0.03}},
                      Scene{"RADIAL", {2400, 1500, 1000, -0.03, 0.01}},
                      Scene{"OPENCV", {2400, 2400, 1505, 995, -0.03, 0.01, 2e-4, -1e-4}},
                      Scene{"FULL_OPENCV",
                            {2400, 2400, 1505, 995, -0.03, 0.01, 2e-4, -1e-4, 1e-3, 0, 0, 0}}),
    [](const auto& info) { return info.param.model; });

TEST(ColmapImportErrors, UnsupportedModelNamesTheLine) {
  testing::TempDir dir("aerocal_colmap_bad");
  std::ofstream(dir.File("cameras.txt")) << "# c\n1 FISHEYE 100 100 1 2 3 4\n";
  std::ofstream(dir.File("images.txt")) << "";
  std::ofstream(dir.File("points3D.txt")) << "";
  ColmapImportOptions options;
  options.folder = dir.path();
  try {
    ImportColmapModel(options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.txt:2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace aerocal::triangulation

#include "calib/camera/convert_camera.h"
#include "triangulation/import/colmap_export.h"
#include "triangulation/simulation/flight_simulator.h"

namespace aerocal::triangulation {
namespace {

// The simulated flight's true block (camera, exposures, observations) and its point truth.
Project TruthBlock(const SimulatedFlight& f, std::map<std::string, Eigen::Vector3d>* points) {
  Project p;
  p.cameras["cam1"] = f.truth;
  p.exposures = f.exposures_truth;
  p.observations = f.observations;
  for (const auto& g : f.points_truth) (*points)[g.id] = *g.xyz_m;
  return p;
}

TEST(ColmapExport, RoundTripKeepsOrientationsAndPixels) {
  FlightSimulationOptions o;
  o.ground_points = 30;
  o.tie_points = 50;
  const SimulatedFlight f = SimulateFlight(o);
  std::map<std::string, Eigen::Vector3d> points;
  Project p = TruthBlock(f, &points);
  p.cameras["cam1"].interior = f.nominal.interior;  // no distortion: exported exactly
  testing::TempDir dir("aerocal_colmap_export");
  WriteColmapModel(p, points, dir.path());
  ColmapImportOptions options;
  options.folder = dir.path();
  options.pixel_size_mm = f.truth.pixel_size_mm;
  const Project back = ImportColmapModel(options).project;
  ASSERT_EQ(back.exposures.size(), p.exposures.size());
  for (size_t i = 0; i < p.exposures.size(); ++i) {
    const Exposure* e = back.FindExposure(p.exposures[i].image);
    ASSERT_NE(e, nullptr);
    EXPECT_LT((e->center_m - p.exposures[i].center_m).norm(), 1e-6);
    EXPECT_LT((calib::RotationFromOpk(e->opk_rad) - calib::RotationFromOpk(p.exposures[i].opk_rad))
                  .norm(),
              1e-12);
  }
  ASSERT_EQ(back.observations.size(), p.observations.size());
  const auto& camera = back.cameras.begin()->second;
  EXPECT_NEAR(camera.c_mm(), f.nominal.c_mm(), 1e-9);
  for (int k = 1; k < calib::BrownFraser10Model::kNumParams; ++k)
    EXPECT_NEAR(camera.interior[k], 0.0, 1e-12);
  std::map<std::pair<std::string, std::string>, Eigen::Vector2d> original;
  for (const auto& ob : p.observations) original[{ob.image, ob.point}] = ob.pixel;
  // Points are renumbered 1..n in id order; compare by image and coordinates.
  std::map<std::string, std::string> id_of_number;
  int n = 0;
  for (const auto& [id, xyz] : points) id_of_number[std::to_string(++n)] = id;
  for (const auto& ob : back.observations)
    EXPECT_LT((ob.pixel - original.at({ob.image, id_of_number.at(ob.point)})).norm(), 1e-9);
}

calib::ModelCamera Registry(const calib::Camera& c) {
  return {calib::CameraModelId::kBrownFraser10, {c.interior.begin(), c.interior.end()}, c.frame()};
}

TEST(ColmapExport, DistortionIsFittedIntoOpenCvNotDropped) {
  FlightSimulationOptions o;  // the simulated camera: 1.7 px radial distortion at the corner
  o.ground_points = 10;
  o.tie_points = 10;
  const SimulatedFlight f = SimulateFlight(o);
  std::map<std::string, Eigen::Vector3d> points;
  const Project p = TruthBlock(f, &points);
  testing::TempDir dir("aerocal_colmap_export_distortion");
  const std::vector<std::string> notes = WriteColmapModel(p, points, dir.path());
  ASSERT_EQ(notes.size(), 1u);
  std::printf("%s\n", notes[0].c_str());
  EXPECT_NE(notes[0].find("least-squares fit"), std::string::npos) << notes[0];
  ColmapImportOptions options;
  options.folder = dir.path();
  options.pixel_size_mm = f.truth.pixel_size_mm;
  const ColmapImportReport back = ImportColmapModel(options);
  std::printf("%s\n", back.notes.front().c_str());
  const calib::Camera& imported = back.project.cameras.begin()->second;
  // Through COLMAP's OPENCV (no K3, no shear B2) and back: within 0.1 px over the format (the
  // shear's 0.048 px at the top and bottom edge dominates), while dropping the distortion would
  // leave pixels.
  const calib::ConversionResidual kept =
      calib::CompareCameras(Registry(f.truth), Registry(imported), 41);
  std::printf(
      "ours -> COLMAP OPENCV -> ours: rms %.3g px, max %.3g px\n", kept.rms_px, kept.max_px);
  EXPECT_LT(kept.max_px, 0.1);
  calib::Camera dropped = f.truth;
  for (int k = calib::BrownFraser10Model::kK1; k < calib::BrownFraser10Model::kNumParams; ++k)
    dropped.interior[k] = 0.0;
  EXPECT_GT(calib::CompareCameras(Registry(f.truth), Registry(dropped), 41).max_px, 1.0);
}

}  // namespace
}  // namespace aerocal::triangulation
