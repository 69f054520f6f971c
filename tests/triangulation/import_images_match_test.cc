// aerocal import images --match colmap, then aerocal adjust: the shortest path from a drone
// flight's JPEGs to an adjusted block (issue 34 item 3). Eight real DJI Phantom 3 images of the
// Brighton Beach flight (four of its first and four of its third strip, about 25 % side overlap;
// 640 x 360 px, metadata as the drone wrote it; tests/data/images_brighton/PROVENANCE.md). COLMAP
// (Debian's 3.8, CPU) extracts, matches and reconstructs; its model is aligned to the EXIF GPS
// centres; the block keeps the imported exposures and camera and gains COLMAP's tie points. Skipped
// with a message when colmap is not installed (apt-get install colmap).
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>

namespace aerocal {
namespace {

using testing::RunAerocal;
const std::string kImages = std::string(AEROCAL_TEST_DATA_DIR) + "/images_brighton";

bool ColmapInstalled() { return std::system("colmap help > /dev/null 2>&1") == 0; }

TEST(ImportImagesMatch, ColmapTiesLetTheFlightBeAdjusted) {
  if (!ColmapInstalled()) GTEST_SKIP() << "colmap is not installed (apt-get install colmap)";
  testing::TempDir tmp("aerocal_import_match");
  auto r = RunAerocal("import images " + kImages + " --gnss-sigma-m 5,10 --match colmap --out " +
                      tmp.File("block"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const triangulation::Project p = triangulation::ReadProject(tmp.File("block"));
  ASSERT_EQ(p.exposures.size(), 8u);  // COLMAP registers all eight (about 215 points each)
  std::map<std::string, int> per_image, rays;
  for (const triangulation::ImageObservation& o : p.observations)
    ++per_image[o.image], ++rays[o.point];
  for (const triangulation::Exposure& e : p.exposures) EXPECT_GE(per_image[e.image], 50) << e.image;
  EXPECT_GE(p.points.size(), 300u);  // 628 to 630 with COLMAP 3.8 (its threads vary a little)
  for (const auto& [id, n] : rays) ASSERT_GE(n, 2) << id;
  // A nadir flight: every tie point lies below every centre and within 100 m of the flight's
  // centre horizontally (the model placed by the GNSS centres alone, through ECEF and back).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double lowest_centre = 1e9;
  for (const triangulation::Exposure& e : p.exposures) {
    mean += e.center_m / 8;
    lowest_centre = std::min(lowest_centre, e.center_m.z());
  }
  const double m_per_deg_lat = 111.2e3,
               m_per_deg_lon = m_per_deg_lat * std::cos(mean.y() * M_PI / 180);
  for (const triangulation::GroundPoint& g : p.points) {
    EXPECT_LT(g.xyz_m->z(), lowest_centre) << g.id;
    EXPECT_LT(std::hypot((g.xyz_m->x() - mean.x()) * m_per_deg_lon,
                         (g.xyz_m->y() - mean.y()) * m_per_deg_lat),
              100)
        << g.id;
  }

  r = RunAerocal("adjust --project " + tmp.File("block") + " --out " + tmp.File("r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = testing::ReadJson(tmp.File("r.json"));
  EXPECT_TRUE(j["converged"].get<bool>());
  // SIFT keypoints on 640 x 360 px images: 0.31 to 0.33 px against the a-priori 1 px.
  EXPECT_GT(j["sigma0"].get<double>(), 0.1);
  EXPECT_LT(j["sigma0"].get<double>(), 1.0);
  std::map<std::string, const triangulation::Exposure*> imported;
  for (const triangulation::Exposure& e : p.exposures) imported[e.image] = &e;
  double shift2 = 0;
  for (const auto& a : j["exposures"]) {
    const triangulation::Exposure& e = *imported.at(a["image"].get<std::string>());
    SCOPED_TRACE(e.image);
    const Eigen::Vector3d shift((a["X"].get<double>() - e.center_m.x()) * m_per_deg_lon,
                                (a["Y"].get<double>() - e.center_m.y()) * m_per_deg_lat,
                                a["Z"].get<double>() - e.center_m.z());
    shift2 += shift.squaredNorm() / 8;
    // The images confirm the attitude from the gimbal angles: within 5 deg, the accuracy of a
    // consumer drone's gimbal and compass (measured: omega +0.8..+2.7, kappa +2.3..+3.5 deg).
    const Eigen::Vector3d opk_deg(
        a["omega"].get<double>(), a["phi"].get<double>(), a["kappa"].get<double>());
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(std::remainder(opk_deg[k] - e.opk_rad[k] * 180 / M_PI, 360), 0, 5) << k;
  }
  // The GNSS centres agree with the photogrammetric geometry to well under their 5 m sigma: the
  // decoded positions (degrees, minutes, seconds, W negative) are the ones the images were taken
  // at (measured: 0.34 m RMS).
  EXPECT_LT(std::sqrt(shift2), 1.5);
  std::printf("tie points %zu, observations %zu, sigma0 %.3f, GNSS shift RMS %.2f m\n",
              p.points.size(),
              p.observations.size(),
              j["sigma0"].get<double>(),
              std::sqrt(shift2));
}

TEST(ImportImagesMatch, SpatialMatcherAndTheOtherColmapOptions) {
  if (!ColmapInstalled()) GTEST_SKIP() << "colmap is not installed (apt-get install colmap)";
  testing::TempDir tmp("aerocal_import_spatial");
  const auto r =
      RunAerocal("import images " + kImages +
                 " --gnss-sigma-m 5,10 --match colmap --colmap colmap "
                 "--colmap-matcher spatial --colmap-max-image-px 640 --colmap-align-error-m 5 "
                 "--sigma-px 0.5 --out " +
                 tmp.File("block"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(tmp.File("block/colmap/spatial_matcher.log")));
  const triangulation::Project p = triangulation::ReadProject(tmp.File("block"));
  EXPECT_EQ(p.exposures.size(), 8u);
  EXPECT_GE(p.points.size(), 300u);  // 492 with COLMAP 3.8 (pairs within 100 m of the EXIF GPS)
  for (const triangulation::ImageObservation& o : p.observations) ASSERT_EQ(o.sigma_px, 0.5);
}

TEST(ImportImagesMatch, AColmapThatCannotRunIsABadOptionAndNothingIsWritten) {
  testing::TempDir tmp("aerocal_import_match_bad");
  const auto r = RunAerocal("import images " + kImages + " --match colmap --colmap " +
                            tmp.File("no_colmap") + " --out " + tmp.File("block"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--match colmap: cannot run"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("block/project.yaml")));
  for (const std::string bad : {"--match sift",
                                "--colmap-matcher sequential",
                                "--colmap-max-image-px 10",
                                "--colmap-align-error-m 0",
                                "--sigma-px -1"}) {
    const auto b = RunAerocal("import images " + kImages + " --match colmap " + bad + " --out " +
                              tmp.File("b"));
    EXPECT_EQ(b.exit_code, 2) << bad << "\n" << b.output;
    EXPECT_NE(b.output.find(bad.substr(0, bad.find(' '))), std::string::npos) << bad << "\n"
                                                                              << b.output;
  }
}

}  // namespace
}  // namespace aerocal
