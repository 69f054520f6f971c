// aerocal import (ODM gcp_list.txt, DBAT marks) then aerocal adjust on the written block files.
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"
#include "triangulation/import/colmap_export.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace aerocal {
namespace {

using testing::RunAerocal;

TEST(ImportCommand, OdmListImportedOnceThenAdjustedWithItsBlundersListed) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_br_uav_gcp_block is absent";
  testing::TempDir tmp("aerocal_import_odm");
  WriteFileAtomically(tmp.File("sx260.yaml"),
                      "name: Canon PowerShot SX260 HS\npixel_size_mm: 0.00154959\n"
                      "format_px: [4000, 3000]\ninterior: {c: 4.5}\n");
  auto r =
      RunAerocal("import odm --gcp-list " + dir + "/odm_gcp_br/gcp_list_floatxy_raw.txt --camera " +
                 tmp.File("sx260.yaml") + " --control " + dir +
                 "/odm_gcp_br/gcp_list_raw.txt --out " + tmp.File("block"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunAerocal("adjust --project " + tmp.File("block") + " --robust-start --out " +
                 tmp.File("r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = aerocal::testing::ReadJson(tmp.File("r.json"));
  int gross = 0;
  for (const auto& o : j["rejected"]) gross += o["residual_px"].get<double>() > 100.0;
  EXPECT_EQ(gross, 2);
  EXPECT_GE(j["check"]["n"].get<int>(), 10);
  EXPECT_NE(j["frame"].get<std::string>().find("+zone=22 +south"), std::string::npos);
}

TEST(ImportCommand, BadGcpLineExitsTwoWithItsLine) {
  testing::TempDir tmp("aerocal_import_bad");
  WriteFileAtomically(
      tmp.File("cam.yaml"),
      "name: c\npixel_size_mm: 0.0015\nformat_px: [4000, 3000]\ninterior: {c: 4.5}\n");
  WriteFileAtomically(tmp.File("gcp.txt"),
                      "EPSG:32722\n1 2 3 10 10 a.jpg P1\n1 2 x 10 10 b.jpg P1\n");
  const auto r = RunAerocal("import odm --gcp-list " + tmp.File("gcp.txt") + " --camera " +
                            tmp.File("cam.yaml") + " --out " + tmp.File("block"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("gcp.txt:3"), std::string::npos) << r.output;
}

TEST(ImportCommand, GeographicGcpListIsRefusedWhateverItsSpelling) {
  testing::TempDir tmp("aerocal_import_geographic");
  WriteFileAtomically(
      tmp.File("cam.yaml"),
      "name: c\npixel_size_mm: 0.0015\nformat_px: [4000, 3000]\ninterior: {c: 4.5}\n");
  for (const char* projection : {"+proj=longlat +datum=WGS84 +no_defs",
                                 "+proj=latlong +ellps=WGS84",
                                 "EPSG:4326",
                                 "WGS84"}) {
    WriteFileAtomically(tmp.File("gcp.txt"),
                        std::string(projection) + "\n-48.5 -27.6 3 10 10 a.jpg P1\n");
    const auto r = RunAerocal("import odm --gcp-list " + tmp.File("gcp.txt") + " --camera " +
                              tmp.File("cam.yaml") + " --out " + tmp.File("block"));
    EXPECT_EQ(r.exit_code, 2) << projection << ": " << r.output;
    EXPECT_NE(r.output.find("gcp.txt:1: geographic"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("block/project.yaml")));
  }
}

TEST(ImportCommand, ColmapModelImportedOnceThenAdjusted) {
  // A simulated block without distortion written as a COLMAP text model (OPENCV camera), imported
  // by the command and adjusted as a free network: sigma0 at the injected 0.2 px.
  triangulation::FlightSimulationOptions o;
  o.interior_correction = {};  // truth = nominal, no distortion: COLMAP's OPENCV holds it exactly
  o.ground_points = 60;
  o.tie_points = 300;
  const triangulation::SimulatedFlight f = triangulation::SimulateFlight(o);
  triangulation::Project block;
  block.cameras["cam1"] = f.truth;
  block.exposures = f.exposures_truth;
  block.observations = f.observations;
  std::map<std::string, Eigen::Vector3d> points;
  for (const auto& g : f.points_truth) points[g.id] = *g.xyz_m;
  testing::TempDir tmp("aerocal_import_colmap");
  triangulation::WriteColmapModel(block, points, tmp.File("model"));
  const auto imported =
      RunAerocal("import colmap --colmap-model " + tmp.File("model") +
                 " --pixel-size-mm 0.009 --sigma-px 0.2 --out " + tmp.File("block"));
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto adjusted = RunAerocal("adjust --project " + tmp.File("block/project.yaml") +
                                   " --out " + tmp.File("r.json"));
  ASSERT_EQ(adjusted.exit_code, 0) << adjusted.output;
  const auto doc = aerocal::testing::ReadJson(tmp.File("r.json"));
  EXPECT_NE(doc["datum"].get<std::string>().find("free network"), std::string::npos);
  EXPECT_NEAR(doc["sigma0_px"].get<double>(), 0.2, 0.02);
}

}  // namespace
}  // namespace aerocal
