// Rig exposure -> virtual image (stitch/rig/rig_convert.h, `aerocal rig convert`): the plane
// homography against the exact conversion, and a real photograph projected through a simulated
// two-head rig and converted back: geometric error measured by the gradient-based shift estimate
// (< 0.1 px where the plane is exact; a 5 % wrong height is seen), no seam (measured as
// tests/stitch/virtual_image_test.cc does), and the command on TIFF files.
#include "stitch/rig/rig_convert.h"

#include "calib/camera/convert_camera.h"
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/yaml_util.h"
#include "stitch/resample/tiff_raster.h"
#include "tests/support/cubic_sample.h"
#include "tests/support/test_support.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

namespace aerocal::stitch {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kHeight = 100.0;

// Virtual camera 1600 x 1200 px, c / p = 1000 px; head A looking 5 deg right from the virtual
// centre, head B 0.5 m to the right looking 5 deg left, slightly rolled and yawed; both
// 1300 x 1100 px, no distortion.
calib::Rig TwoHeadRig() {
  calib::Rig rig;
  rig.name = "two-head test rig";
  rig.reference_head = "A";
  rig.virtual_camera = calib::VirtualCamera::Pinhole(
      calib::VirtualOrientation::kRig, 10.0, 0.01, 1600, 1200, 0.0, 0.0, kHeight);
  for (int k = 0; k < 2; ++k) {
    calib::RigHead head;
    head.id = k == 0 ? "A" : "B";
    head.camera.pixel_size_mm = 0.01;
    head.camera.width_px = 1300;
    head.camera.height_px = 1100;
    head.camera.interior = {10.0 + 0.05 * k, 0.02 * k, -0.03 * k, 0, 0, 0, 0, 0, 0, 0};
    head.mount_rad = k == 0 ? Eigen::Vector3d(0, -5 * kDeg, 0)
                            : Eigen::Vector3d(0.3 * kDeg, 5 * kDeg, 0.5 * kDeg);
    head.lever_arm_m = k == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.5, 0.02, 0.05);
    rig.heads.push_back(head);
  }
  return rig;
}

TEST(RigConvert, PlaneHomographyIsTheExactConversion) {
  for (const auto orientation :
       {calib::VirtualOrientation::kRig, calib::VirtualOrientation::kLevel}) {
    calib::Rig rig = TwoHeadRig();
    rig.virtual_camera.orientation = orientation;
    RigExposure exposure;
    exposure.rig_opk_rad = Eigen::Vector3d(0.02, -0.03, 0.4);
    exposure.rig_center_m = Eigen::Vector3d(300.0, -100.0, 250.0);
    exposure.velocity_mps = Eigen::Vector3d(40, 2, 0);
    exposure.dt_s = {0.0, 0.003};
    const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, kHeight));
    for (int k = 0; k < 2; ++k) {
      const Eigen::Matrix3d h = HeadFromVirtualHomography(converter, k);
      for (const Eigen::Vector2d& v : {Eigen::Vector2d(0, 0),
                                       Eigen::Vector2d(800, 600),
                                       Eigen::Vector2d(1599, 1199),
                                       Eigen::Vector2d(200, 1000)}) {
        const Eigen::Vector3d p = h * v.homogeneous();
        const auto exact = converter.HeadFromVirtual(k, v);
        ASSERT_TRUE(exact.has_value());
        EXPECT_LT((p.hnormalized() - *exact).norm(), 1e-7) << "head " << k;
      }
    }
  }
}

// Both heads with radial, decentering and affinity terms of several pixels at the corners.
calib::Rig DistortedTwoHeadRig() {
  calib::Rig rig = TwoHeadRig();
  using Model = calib::BrownFraser10Model;
  rig.heads[0].camera.interior[Model::kK1] = 1e-4;  // 6 px at the corner (r = 8.5 mm)
  rig.heads[0].camera.interior[Model::kP1] = 3e-5;
  rig.heads[1].camera.interior[Model::kK1] = -8e-5;
  rig.heads[1].camera.interior[Model::kK2] = 5e-7;
  rig.heads[1].camera.interior[Model::kP2] = -2e-5;
  rig.heads[1].camera.interior[Model::kB1] = 2e-4;
  return rig;
}

// Largest distance (px) between homography + bilinear grid of `base` and the exact conversion of
// `exact` at pseudo-random virtual pixels inside head k; `checked` counts them.
double WorstGridError(const RigConverter& base,
                      const RigConverter& exact,
                      int k,
                      const MapCorrectionGrid& g,
                      int samples,
                      int* checked) {
  const Eigen::Matrix3d h = HeadFromVirtualHomography(base, k);
  double worst = 0.0;
  *checked = 0;
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector2d v(std::fmod(i * 389.17, 1599.0), std::fmod(i * 257.31, 1199.0));
    const auto p = exact.HeadFromVirtual(k, v);
    if (!p || !exact.InHeadFormat(k, *p)) continue;
    const double gu = v.x() / g.step_px, gv = v.y() / g.step_px;
    const int ci = std::min(static_cast<int>(gu), g.cols - 2),
              cj = std::min(static_cast<int>(gv), g.rows - 2);
    const double fu = gu - ci, fv = gv - cj;
    Eigen::Vector2d d = Eigen::Vector2d::Zero();
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const size_t at = 2 * (static_cast<size_t>(cj + dj) * g.cols + ci + di);
        d += (di ? fu : 1 - fu) * (dj ? fv : 1 - fv) * Eigen::Vector2d(g.duv[at], g.duv[at + 1]);
      }
    worst = std::max(worst, ((h * v.homogeneous()).hnormalized() + d - *p).norm());
    ++*checked;
  }
  return worst;
}

TEST(RigConvert, CorrectionGridsCarryTheDistortionToTheTolerance) {
  const calib::Rig rig = DistortedTwoHeadRig();
  RigExposure exposure;
  exposure.rig_opk_rad = Eigen::Vector3d(0.01, -0.02, 0.3);
  const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, kHeight));
  const HeadMapCorrections corrections = MakeHeadMapCorrections(converter, 0.01);
  ASSERT_EQ(corrections.grids.size(), 2u);
  EXPECT_LE(corrections.max_error_px, 0.01);
  EXPECT_GT(corrections.finest_step_px, 2);
  // Independent check at pseudo-random virtual pixels inside each head: homography + bilinear
  // grid against the exact conversion.
  for (int k = 0; k < 2; ++k) {
    const MapCorrectionGrid& g = corrections.grids[k];
    ASSERT_GT(g.step_px, 0);
    EXPECT_GT(g.max_abs_px, 2.0f) << "the distortion is several pixels";
    int checked = 0;
    const double worst = WorstGridError(converter, converter, k, g, 4000, &checked);
    EXPECT_GT(checked, 1000);
    EXPECT_LT(worst, 0.02) << "head " << k;  // 0.01 per axis at cell centres; float storage
  }
  // Distortion-free heads need no grid.
  const RigConverter plain(
      TwoHeadRig(), exposure, MakeRectificationPlane(TwoHeadRig(), exposure, kHeight));
  const HeadMapCorrections none = MakeHeadMapCorrections(plain);
  EXPECT_EQ(none.finest_step_px, 0);
  EXPECT_EQ(none.grids[0].step_px, 0);
}

// Coverage of strongly tilted heads (the uav4 rig of configs/rig_uav4.yaml: B and D tilted 37 deg
// across track, looking away from each other, so they share no ground point): head k covers a
// virtual pixel exactly where the exact conversion lands in its format. Two faults made B and D
// "overlap" in the far corners of the level image: (1) the resampler scaled its inverse
// homography by its (2, 2) entry, negative for a head whose horizon the virtual pixel (0, 0) lies
// beyond (D), which flipped the sign its column bounds assume (distortion-free heads); (2) the
// correction grid interpolated between nodes on either side of a head's horizon, where the map
// diverges (distorted heads). Checked on every 3rd virtual pixel at 1/10 of the formats, with and
// without distortion.
// configs/rig_uav4.yaml at 0.1 x its formats (pixels 10 x larger), with K1 = 2e-5 in every head
// (~2.5 px at the corner: correction grids) when `distorted`.
calib::Rig SmallUav4Rig(bool distorted) {
  calib::Rig rig = calib::ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_uav4.yaml");
  const auto scale = [](int& width, int& height, double& pixel_mm) {
    width /= 10, height /= 10, pixel_mm *= 10;
  };
  scale(rig.virtual_camera.camera.width_px,
        rig.virtual_camera.camera.height_px,
        rig.virtual_camera.camera.pixel_size_mm);
  for (auto& head : rig.heads) {
    scale(head.camera.width_px, head.camera.height_px, head.camera.pixel_size_mm);
    if (distorted) head.camera.interior[calib::BrownFraser10Model::kK1] = 2e-5;
  }
  return rig;
}

// A slightly tilted, turned exposure 100 m above the rectification plane.
RigExposure TurnedExposure() {
  RigExposure exposure;
  exposure.rig_opk_rad = Eigen::Vector3d(0.002, -0.001, 0.3);
  exposure.rig_center_m = Eigen::Vector3d(0, 0, 400);
  return exposure;
}

TEST(RigConvert, TiltedHeadsCoverExactlyTheVirtualPixelsTheySee) {
  for (const bool distorted : {false, true}) {
    const calib::Rig rig = SmallUav4Rig(distorted);
    const RigExposure exposure = TurnedExposure();
    const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, 300.0));
    const calib::Camera all = RigExposureAsSubimageCamera(converter);
    const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
    const int width = all.width_px, height = all.height_px;
    std::vector<MemoryRaster> covered;
    for (int k = 0; k < 4; ++k) {
      calib::Camera one = all;
      one.subimages = {all.subimages[k]};
      MemoryRaster white({rig.heads[k].camera.width_px, rig.heads[k].camera.height_px, 1, 8});
      std::fill(white.bytes().begin(), white.bytes().end(), 255);
      covered.emplace_back(RasterInfo{width, height, 1, 8});
      ResampleOptions options;
      options.fill = 0.0;
      ResampleVirtualImage(
          one, {&white}, &covered.back(), options, std::vector<MapCorrectionGrid>{grids.grids[k]});
    }
    long b_and_d = 0;
    for (int k = 0; k < 4; ++k) {
      long seen = 0, wrong = 0;
      for (int r = 0; r < height; r += 3)
        for (int c = 0; c < width; c += 3) {
          const auto exact = converter.HeadFromVirtual(k, Eigen::Vector2d(c, r));
          const calib::Camera& camera = rig.heads[k].camera;
          // 0.5 px band at the format's border: the grid's tolerance and float rounding decide.
          const auto inside = [&](double margin) {
            return exact && exact->x() >= -margin && exact->y() >= -margin &&
                   exact->x() <= camera.width_px - 1 + margin &&
                   exact->y() <= camera.height_px - 1 + margin;
          };
          const bool is_covered = covered[k].At(c, r) > 0;
          seen += is_covered;
          if (is_covered ? !inside(0.5) : inside(-0.5)) ++wrong;
          if (k == 1 && is_covered && covered[3].At(c, r) > 0) ++b_and_d;
        }
      EXPECT_GT(seen, 10000) << rig.heads[k].id << (distorted ? " distorted" : "");
      EXPECT_EQ(wrong, 0) << rig.heads[k].id << (distorted ? " distorted" : "");
    }
    EXPECT_EQ(b_and_d, 0) << (distorted ? "distorted" : "distortion-free");
  }
}

// Head k's images as ramps (16 bit, 16 x the head column, or row) resampled onto the virtual image
// with its correction grid: the resampled value / 16 is the sampled head position (bilinear and
// bicubic interpolation of a ramp are exact inside the format), compared with the exact map at
// every virtual pixel whose head pixel lies 1 px inside the format (the bicubic support and the
// coverage rule stay out of it).
struct RampCheck {
  long checked = 0, wrong = 0;
  double worst_px = 0.0;
};
RampCheck SampleRamps(const RigConverter& converter,
                      const HeadMapCorrections& grids,
                      int k,
                      const ResampleOptions& options,
                      double tolerance_px) {
  const calib::Camera all = RigExposureAsSubimageCamera(converter);
  const int width = all.width_px, height = all.height_px;
  calib::Camera one = all;
  one.subimages = {all.subimages[k]};
  const calib::Camera& camera = converter.rig().heads[k].camera;
  std::array<MemoryRaster, 2> ramp{MemoryRaster({camera.width_px, camera.height_px, 1, 16}),
                                   MemoryRaster({camera.width_px, camera.height_px, 1, 16})};
  for (int r = 0; r < camera.height_px; ++r)
    for (int c = 0; c < camera.width_px; ++c) {
      ramp[0].Set(c, r, 0, 16.0 * c);
      ramp[1].Set(c, r, 0, 16.0 * r);
    }
  std::array<MemoryRaster, 2> out{MemoryRaster({width, height, 1, 16}),
                                  MemoryRaster({width, height, 1, 16})};
  for (int a = 0; a < 2; ++a)
    ResampleVirtualImage(
        one, {&ramp[a]}, &out[a], options, std::vector<MapCorrectionGrid>{grids.grids[k]});
  RampCheck check;
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const auto exact = converter.HeadFromVirtual(k, Eigen::Vector2d(c, r));
      if (!exact || exact->x() < 1 || exact->y() < 1 || exact->x() > camera.width_px - 2 ||
          exact->y() > camera.height_px - 2)
        continue;
      const Eigen::Vector2d sampled(out[0].At(c, r) / 16.0, out[1].At(c, r) / 16.0);
      const double error = (sampled - *exact).cwiseAbs().maxCoeff();
      check.worst_px = std::max(check.worst_px, error);
      ++check.checked;
      check.wrong += error > tolerance_px;
    }
  return check;
}

// The grid's tolerance (0.01 px), the 16-bit rounding (1/32 px) and float rounding.
constexpr double kRampTolerancePx = 0.05;

// Every covered virtual pixel takes its value from the head pixel its exact map gives, with a
// correction grid too. A sample outside the strip's source window must never be clamped to the
// window's edge (a wrong value); short strips (16 rows), the default (256) and one strip for the
// whole image (4096 rows: a strip that reaches beyond a tilted head's horizon).
TEST(RigConvert, TiltedHeadsSampleTheExactHeadPixelInEveryStrip) {
  const calib::Rig rig = SmallUav4Rig(/*distorted=*/true);
  const RigExposure exposure = TurnedExposure();
  const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, 300.0));
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  for (const int strip_rows : {16, 256, 4096})
    for (const Interpolation interpolation : {Interpolation::kBilinear, Interpolation::kBicubic})
      for (int k = 0; k < 4; ++k) {
        ResampleOptions options;
        options.fill = 0.0;
        options.strip_rows = strip_rows;
        options.interpolation = interpolation;
        const RampCheck check = SampleRamps(converter, grids, k, options, kRampTolerancePx);
        EXPECT_GT(check.checked, 10000) << rig.heads[k].id;
        EXPECT_EQ(check.wrong, 0) << rig.heads[k].id << ", strips of " << strip_rows << " rows, "
                                  << (interpolation == Interpolation::kBilinear ? "bilinear"
                                                                                : "bicubic")
                                  << ": worst " << check.worst_px << " px";
      }
}

// The virtual camera in another model, with distortion of its own (OpenCV's, k1 = -0.005: about
// 20 px at the corner of the small uav4 format) and distortion-free heads: the homography between
// the pinhole parts is no longer the map, so every head gets a correction grid, and the converted
// image samples the exact head pixel (the virtual camera's own model) to the same tolerance.
TEST(RigConvert, AVirtualCameraWithDistortionIsConvertedThroughItsOwnModel) {
  calib::Rig rig = SmallUav4Rig(/*distorted=*/false);
  calib::Camera& v = rig.virtual_camera.camera;
  v = v.WithModelCamera(
      calib::ConvertCamera(v.AsModelCamera(), calib::CameraModelId::kOpenCv).camera);
  v.interior[v.ParamIndex("k1")] = -0.005;
  const calib::Rig written =
      calib::ParseRig(LoadYamlText(calib::RigToYaml(rig), "rig.yaml"), "rig.yaml");
  EXPECT_EQ(written.virtual_camera.camera.model, calib::CameraModelId::kOpenCv);
  EXPECT_EQ(written.virtual_camera.camera.interior, v.interior);
  const RigExposure exposure = TurnedExposure();
  const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, 300.0));
  // The ray of a virtual pixel goes through the virtual camera's model and back.
  const Eigen::Vector2d corner(0, 0);
  const auto ray = rig.virtual_camera.RayFromPixel(corner);
  ASSERT_TRUE(ray.has_value());
  Eigen::Vector2d back;
  ASSERT_TRUE(rig.virtual_camera.PixelFromRay(*ray, &back));
  EXPECT_LT((back - corner).norm(), 1e-9);
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  EXPECT_GT(grids.finest_step_px, 0);
  ResampleOptions options;
  options.fill = 0.0;
  for (int k = 0; k < 4; ++k) {
    EXPECT_GT(grids.grids[k].max_abs_px, 1.0) << rig.heads[k].id;
    const RampCheck check = SampleRamps(converter, grids, k, options, kRampTolerancePx);
    EXPECT_GT(check.checked, 10000) << rig.heads[k].id;
    EXPECT_EQ(check.wrong, 0) << rig.heads[k].id << ": worst " << check.worst_px << " px";
  }
}

// A DEM of a tilted plane is a tilted rectification plane (bilinear interpolation of a plane is
// exact): the homography of the level plane plus the DEM grids reproduce the tilted plane's exact
// conversion; and the reader names the line of a bad DEM.
std::string TiltedDem(const testing::TempDir& dir) {
  std::string text =
      "ncols 61\nnrows 51\nxllcorner -152.5\nyllcorner -127.5\ncellsize 5\n"
      "NODATA_value -9999\n";
  for (int r = 50; r >= 0; --r) {  // north row first
    for (int c = 0; c <= 60; ++c) {
      const double x = -150.0 + 5.0 * c, y = -125.0 + 5.0 * r;
      text += FormatNumber(-100.0 + 0.05 * x - 0.03 * y) + (c < 60 ? " " : "\n");
    }
  }
  WriteFileAtomically(dir.File("tilted.asc"), text);
  return dir.File("tilted.asc");
}

TEST(RigConvert, DemOfATiltedPlaneIsThatPlane) {
  testing::TempDir dir;
  const DemGrid dem = ReadDemAscii(TiltedDem(dir));
  ASSERT_EQ(dem.cols, 61);
  EXPECT_NEAR(*dem.HeightAt(10.0, 20.0), -100.0 + 0.5 - 0.6, 1e-12);
  const calib::Rig rig = DistortedTwoHeadRig();
  RigExposure exposure;
  exposure.rig_opk_rad = Eigen::Vector3d(0.01, -0.02, 0.3);
  const RigConverter level(rig, exposure, MakeRectificationPlane(rig, exposure, kHeight));
  RectificationPlane tilted;
  tilted.normal = Eigen::Vector3d(-0.05, 0.03, 1.0).normalized();
  tilted.offset = tilted.normal.dot(Eigen::Vector3d(0, 0, -100.0));
  const RigConverter oracle(rig, exposure, tilted);
  const HeadMapCorrections corrections = MakeHeadMapCorrections(level, 0.01, &dem);
  EXPECT_LE(corrections.max_error_px, 0.01);
  for (int k = 0; k < 2; ++k) {
    const MapCorrectionGrid& g = corrections.grids[k];
    ASSERT_GT(g.step_px, 0) << "over a DEM every head has a grid";
    EXPECT_GT(g.max_abs_px, 1.0f) << "the tilt moves the map by pixels";
    int checked = 0;
    const double worst = WorstGridError(level, oracle, k, g, 3000, &checked);
    EXPECT_GT(checked, 1000);
    EXPECT_LT(worst, 0.02) << "head " << k;
  }
  // Bad DEMs: FILE:LINE. The last one is a header of 1e6 x 1e6 heights (8 TB) over a few bytes,
  // refused at the header before anything is allocated.
  const struct {
    const char* file;
    const char* text;
    const char* expected;
  } bad_dems[] = {
      {"bad.asc",
       "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize -1\n1 2 3\n4 5 6\n",
       "bad.asc:5: cellsize must be > 0"},
      {"short.asc",
       "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 x 6\n",
       "short.asc:7: expected 3 heights, got 1"},
      {"huge.asc",
       "ncols 1000000\nnrows 1000000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n",
       "huge.asc:2: ncols x nrows = 1e+12 heights"},
      {"twice.asc",
       "ncols 2\nnrows 2\nNCOLS 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n",
       "twice.asc:3: duplicate header 'ncols'"},
      {"unknown.asc",
       "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nzone 33\n1 2\n3 4\n",
       "unknown.asc:6: unknown header 'zone'"},
      {"nocell.asc",
       "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\n1 2\n3 4\n",
       "nocell.asc:5: missing header 'cellsize'"},
      {"two.asc", "ncols 2 3\nnrows 2\n", "two.asc:1: header 'ncols' needs one number"},
      {"rows.asc",
       "ncols 2\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1.0 2.0\n3.0 4.0\n",
       "rows.asc:8: expected 3 rows of heights, got 2"},
      {"wide.asc",
       "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 9\n3 4\n",
       "wide.asc:6: more than 2 heights"},
      {"empty.asc",
       "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9\n-9 -9\n-9 "
       "-9\n",
       "empty.asc: the DEM has no valid height"},
  };
  for (const auto& bad : bad_dems) {
    WriteFileAtomically(dir.File(bad.file), bad.text);
    try {
      ReadDemAscii(dir.File(bad.file));
      ADD_FAILURE() << bad.file << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad.expected), std::string::npos) << e.what();
    }
  }
}

using testing::SampleCubic;

// The head images of a photograph lying on the rectification plane: the photograph is the
// virtual image, so head pixel -> virtual pixel (exact conversion) -> the photograph there.
std::vector<MemoryRaster> Photograph(const MemoryRaster& truth, const RigConverter& converter) {
  std::vector<MemoryRaster> heads;
  for (int k = 0; k < static_cast<int>(converter.rig().heads.size()); ++k) {
    const calib::Camera& camera = converter.rig().heads[k].camera;
    MemoryRaster image({camera.width_px, camera.height_px, 1, 8});
    for (int row = 0; row < camera.height_px; ++row)
      for (int col = 0; col < camera.width_px; ++col) {
        const auto v = converter.VirtualFromHead(k, Eigen::Vector2d(col, row));
        image.Set(col, row, 0, SampleCubic(truth, v->x(), v->y()));
      }
    heads.push_back(std::move(image));
  }
  return heads;
}

struct Region {
  double sum = 0, sum2 = 0;
  long n = 0;
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  void Add(double d, const Eigen::Vector2d& gradient) {
    sum += d;
    sum2 += d * d;
    ++n;
    normal += gradient * gradient.transpose();
    rhs += gradient * d;
  }
  double Rms() const { return std::sqrt(sum2 / n); }
  double Mean() const { return sum / n; }
  // Least-squares shift s (px) with back(x) ~ truth(x - s): d = back - truth ~ -g . s.
  Eigen::Vector2d Shift() const { return -normal.ldlt().solve(rhs); }
};

struct Comparison {
  Region only_a, only_b, overlap, edge;
};

// Compares the converted image with the truth over pixels 3 px inside the coverage.
Comparison Compare(const MemoryRaster& back,
                   const MemoryRaster& truth,
                   const RigConverter& converter) {
  Comparison out;
  const RasterInfo info = truth.Info();
  for (int r = 3; r < info.height - 3; ++r)
    for (int c = 3; c < info.width - 3; ++c) {
      int inside[2] = {0, 0};
      bool edge = false;
      bool margin_ok = true;
      for (int k = 0; k < 2; ++k) {
        const auto p = converter.HeadFromVirtual(k, Eigen::Vector2d(c, r));
        const calib::Camera& camera = converter.rig().heads[k].camera;
        const double distance = std::min(std::min(p->x(), camera.width_px - 1 - p->x()),
                                         std::min(p->y(), camera.height_px - 1 - p->y()));
        inside[k] = distance >= 0;
        if (distance >= 0 && distance < 1.5) edge = true;
        if (distance > -3 && distance < 0) margin_ok = false;  // just outside: skip
      }
      if (!margin_ok || !(inside[0] || inside[1])) continue;
      const double d = back.At(c, r) - truth.At(c, r);
      const Eigen::Vector2d g(0.5 * (truth.At(c + 1, r) - truth.At(c - 1, r)),
                              0.5 * (truth.At(c, r + 1) - truth.At(c, r - 1)));
      if (edge) out.edge.Add(d, g);
      if (inside[0] && inside[1])
        out.overlap.Add(d, g);
      else if (inside[0])
        out.only_a.Add(d, g);
      else
        out.only_b.Add(d, g);
    }
  return out;
}

TEST(RigConvert, RealPhotographThroughATwoHeadRigAndBack) {
  const std::string dir = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const MemoryRaster full = ReadImageFile(dir + "/images/img_4880.jpg", /*gray=*/true);
  const calib::Rig rig = TwoHeadRig();
  const int width = rig.virtual_camera.camera.width_px,
            height = rig.virtual_camera.camera.height_px;
  const int x_off = (full.Info().width - width) / 2, y_off = (full.Info().height - height) / 2;
  MemoryRaster truth({width, height, 1, 8});
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) truth.Set(c, r, 0, full.At(c + x_off, r + y_off));

  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, kHeight));
  std::vector<MemoryRaster> heads = Photograph(truth, converter);
  std::vector<RasterSource*> sources = {&heads[0], &heads[1]};
  MemoryRaster back({width, height, 1, 8});
  const ResampleReport report = ConvertRigExposure(converter, sources, &back, {});
  EXPECT_GT(report.overlap, 700000);

  const Comparison cmp = Compare(back, truth, converter);
  for (const auto& [name, region] : {std::pair<const char*, const Region*>{"A only", &cmp.only_a},
                                     {"B only", &cmp.only_b},
                                     {"overlap", &cmp.overlap},
                                     {"edges", &cmp.edge}}) {
    const Eigen::Vector2d shift = region->Shift();
    std::printf("%-8s %7ld px: RMS %.3f DN, mean %.3f DN, shift (%.4f, %.4f) px\n",
                name,
                region->n,
                region->Rms(),
                region->Mean(),
                shift.x(),
                shift.y());
    ASSERT_GT(region->n, 5000) << name;
    // Where the plane is exact the geometry is right to < 0.1 px (expected ~0.01: interpolation).
    EXPECT_LT(shift.norm(), 0.1) << name;
  }
  // No seam: overlaps (two heads averaged) no worse than single coverage, no grey-level step, and
  // the same along the head edges.
  const double rms_single =
      std::sqrt((cmp.only_a.sum2 + cmp.only_b.sum2) / (cmp.only_a.n + cmp.only_b.n));
  const double mean_single = (cmp.only_a.sum + cmp.only_b.sum) / (cmp.only_a.n + cmp.only_b.n);
  EXPECT_LT(cmp.overlap.Rms(), rms_single * 1.1);
  EXPECT_LT(std::abs(cmp.overlap.Mean() - mean_single), 0.1);
  EXPECT_LT(cmp.edge.Rms(), rms_single * 1.1);
  EXPECT_LT(std::abs(cmp.edge.Mean() - mean_single), 0.1);

  // The measurement has teeth: converted at 105 m instead of 100 m, head B (0.5 m from the
  // virtual centre) is off by 1000 px x 0.5 m x (1/100 - 1/105) = 0.24 px; head A (at the centre)
  // is not.
  const RigConverter wrong(rig, nadir, MakeRectificationPlane(rig, nadir, 105.0));
  MemoryRaster off({width, height, 1, 8});
  ConvertRigExposure(wrong, sources, &off, {});
  const Comparison bad = Compare(off, truth, converter);
  std::printf("at 105 m: A only shift %.4f px, B only shift %.4f px\n",
              bad.only_a.Shift().norm(),
              bad.only_b.Shift().norm());
  EXPECT_LT(bad.only_a.Shift().norm(), 0.1);
  EXPECT_NEAR(bad.only_b.Shift().norm(), 0.238, 0.06);
}

TEST(RigConvert, RealPhotographThroughDistortedHeadsAndBack) {
  const std::string dir = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const MemoryRaster full = ReadImageFile(dir + "/images/img_4880.jpg", /*gray=*/true);
  const calib::Rig rig = DistortedTwoHeadRig();
  const int width = rig.virtual_camera.camera.width_px,
            height = rig.virtual_camera.camera.height_px;
  const int x_off = (full.Info().width - width) / 2, y_off = (full.Info().height - height) / 2;
  MemoryRaster truth({width, height, 1, 8});
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) truth.Set(c, r, 0, full.At(c + x_off, r + y_off));
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, kHeight));
  std::vector<MemoryRaster> heads = Photograph(truth, converter);  // through the distortion
  std::vector<RasterSource*> sources = {&heads[0], &heads[1]};
  MemoryRaster back({width, height, 1, 8});
  HeadMapCorrections corrections;
  ConvertRigExposure(converter, sources, &back, {}, &corrections);
  EXPECT_LE(corrections.max_error_px, 0.01);
  const Comparison cmp = Compare(back, truth, converter);
  for (const auto& [name, region] : {std::pair<const char*, const Region*>{"A only", &cmp.only_a},
                                     {"B only", &cmp.only_b},
                                     {"overlap", &cmp.overlap}}) {
    const Eigen::Vector2d shift = region->Shift();
    std::printf("distorted %-8s %7ld px: RMS %.3f DN, shift (%.4f, %.4f) px\n",
                name,
                region->n,
                region->Rms(),
                shift.x(),
                shift.y());
    ASSERT_GT(region->n, 5000) << name;
    EXPECT_LT(shift.norm(), 0.1) << name;
  }
  // Teeth: the homographies alone (distortion ignored) leave pixels of error: a larger grey-level
  // RMS in every region.
  MemoryRaster plain({width, height, 1, 8});
  ResampleVirtualImage(RigExposureAsSubimageCamera(converter), sources, &plain, {});
  const Comparison bad = Compare(plain, truth, converter);
  std::printf("without grids: A only RMS %.3f DN, B only RMS %.3f DN\n",
              bad.only_a.Rms(),
              bad.only_b.Rms());
  EXPECT_GT(bad.only_a.Rms(), 1.5 * cmp.only_a.Rms());
  EXPECT_GT(bad.only_b.Rms(), 1.5 * cmp.only_b.Rms());
}

TEST(RigConvertCommand, WritesTheVirtualTiffAndRefusesBadInput) {
  testing::TempDir tmp;
  const calib::Rig rig = TwoHeadRig();
  calib::WriteRig(tmp.File("rig.yaml"), rig);
  // A synthetic texture (no real data needed): smooth gradients plus a checker pattern.
  MemoryRaster truth({1600, 1200, 1, 8});
  for (int r = 0; r < 1200; ++r)
    for (int c = 0; c < 1600; ++c)
      truth.Set(c, r, 0, 60 + 0.05 * c + 0.04 * r + 50 * (((c / 40) + (r / 40)) % 2));
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, kHeight));
  std::vector<MemoryRaster> heads = Photograph(truth, converter);
  for (int k = 0; k < 2; ++k) {
    TiffWriter writer(tmp.File(rig.heads[k].id + ".tif"), heads[k].Info(), {});
    writer.WriteRows(0, heads[k].Info().height, heads[k].bytes().data());
    writer.Commit();
  }
  const std::string images = " --images A=" + tmp.File("A.tif") + ",B=" + tmp.File("B.tif");
  auto run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") + images +
                                 " --relief-m 10 --out " + tmp.File("virtual.tif"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // 1000 px x |(0.5, 0.02, 0.05)| m x 10 m / (100 m x 90 m) = 0.559 px between the heads.
  EXPECT_NE(run.output.find("relief of 10 m off the plane: 0.559 px between heads A and B"),
            std::string::npos)
      << run.output;
  const auto out = OpenTiff(tmp.File("virtual.tif"));
  EXPECT_EQ(out->Info().width, 1600);
  EXPECT_EQ(out->Info().height, 1200);
  std::vector<std::uint8_t> row(1600);
  out->ReadWindow(0, 620, 1600, 1, row.data());
  for (const int col : {300, 820, 1300})  // inside checker squares: the texture, to interpolation
    EXPECT_NEAR(row[col], truth.At(col, 620), 2.0) << col;
  // Tiled BigTIFF (--tile-px 256 --bigtiff): the same pixels as the stripped classic TIFF.
  run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") + images +
                            " --tile-px 256 --bigtiff --out " + tmp.File("tiled.tif"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(TiffTileWidth(tmp.File("tiled.tif")), 256);
  EXPECT_TRUE(IsBigTiff(tmp.File("tiled.tif")));
  EXPECT_EQ(TiffTileWidth(tmp.File("virtual.tif")), 0);
  {
    const auto tiled = OpenTiff(tmp.File("tiled.tif"));
    ASSERT_EQ(tiled->Info().width, 1600);
    ASSERT_EQ(tiled->Info().height, 1200);
    std::vector<std::uint8_t> a(1600 * 1200), b(1600 * 1200);
    tiled->ReadWindow(0, 0, 1600, 1200, a.data());
    out->ReadWindow(0, 0, 1600, 1200, b.data());
    EXPECT_TRUE(a == b) << "the tiled image differs from the stripped one";
  }
  run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") + images +
                            " --tile-px 100 --out " + tmp.File("v2.tif"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("--tile-px must be 0 (strips) or a multiple of 16"), std::string::npos)
      << run.output;
  // Refusals: exit 2, nothing written.
  run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") +
                            " --images A=" + tmp.File("A.tif") + " --out " + tmp.File("v2.tif"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("no image for head B"), std::string::npos) << run.output;
  run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") + images +
                            " --opk-deg 1,2 --out " + tmp.File("v2.tif"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("--opk-deg"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("v2.tif")));
  // Heads with distortion: photographed through it, converted through the correction grids.
  const calib::Rig distorted = DistortedTwoHeadRig();
  calib::WriteRig(tmp.File("distorted.yaml"), distorted);
  const RigConverter through(distorted, nadir, MakeRectificationPlane(distorted, nadir, kHeight));
  std::vector<MemoryRaster> bent = Photograph(truth, through);
  for (int k = 0; k < 2; ++k) {
    TiffWriter writer(tmp.File("d" + distorted.heads[k].id + ".tif"), bent[k].Info(), {});
    writer.WriteRows(0, bent[k].Info().height, bent[k].bytes().data());
    writer.Commit();
  }
  run = testing::RunAerocal("rig convert --camera " + tmp.File("distorted.yaml") +
                            " --images A=" + tmp.File("dA.tif") + ",B=" + tmp.File("dB.tif") +
                            " --out " + tmp.File("dv.tif"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("heads with distortion: correction grids down to"), std::string::npos)
      << run.output;
  // --dem: a flat DEM at the plane's height gives the plane's image; a bad DEM exits with 2.
  std::string flat = "ncols 3\nnrows 3\nxllcenter -200\nyllcenter -200\ncellsize 200\n";
  for (int r = 0; r < 3; ++r) flat += "-100 -100 -100\n";
  WriteFileAtomically(tmp.File("flat.asc"), flat);
  run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") + images + " --dem " +
                            tmp.File("flat.asc") + " --out " + tmp.File("dem.tif"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("DEM surface: correction grids down to 64 px"), std::string::npos)
      << run.output;
  const auto on_dem = OpenTiff(tmp.File("dem.tif"));
  const auto on_plane = OpenTiff(tmp.File("virtual.tif"));
  std::vector<std::uint8_t> a(1600), b(1600);
  int differing = 0;
  for (int r = 0; r < 1200; r += 37) {
    on_dem->ReadWindow(0, r, 1600, 1, a.data());
    on_plane->ReadWindow(0, r, 1600, 1, b.data());
    for (int c = 0; c < 1600; ++c) differing += std::abs(a[c] - b[c]) > 1;
  }
  EXPECT_LT(differing, 20) << "grey values off by more than 1 DN";
  WriteFileAtomically(tmp.File("broken.asc"), "ncols 3\nnrows 3\nxllcenter 0\ncellsize 1\n1 2 3\n");
  run = testing::RunAerocal("rig convert --camera " + tmp.File("rig.yaml") + images + " --dem " +
                            tmp.File("broken.asc") + " --out " + tmp.File("dem2.tif"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("broken.asc:5: missing header 'yllcorner'"), std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("dem2.tif")));
  const auto bent_back = OpenTiff(tmp.File("dv.tif"));
  bent_back->ReadWindow(0, 620, 1600, 1, row.data());
  for (const int col : {300, 820, 1300}) EXPECT_NEAR(row[col], truth.At(col, 620), 2.0) << col;
}

}  // namespace
}  // namespace aerocal::stitch
