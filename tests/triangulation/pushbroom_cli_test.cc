// `aerocal simulate --pushbroom` and `aerocal pushbroom calibrate`: the files a simulation writes,
// the calibration's JSON keys, the updated camera read back, every option of the command, the
// degenerate runs (exit 3, named warnings, no camera written) and bad input (exit 2, FILE:LINE,
// nothing written). Also the example camera of configs/.
#include "calib/camera/line_camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <tinyxml2.h>

namespace aerocal::triangulation {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;
using nlohmann::json;

const char* kSmall = " --detectors 60 --lines 400 --control 300 --seed 3";

std::string Calibrate(const std::string& dir, const std::string& extra) {
  return "pushbroom calibrate --camera " + dir + "/camera_nominal.yaml --pos " + dir +
         "/pos.csv --observations " + dir + "/observations.csv --points " + dir + "/points.csv " +
         extra;
}

TEST(PushbroomCommands, SimulateThenCalibrate) {
  TempDir dir;
  auto sim = RunAerocal("simulate --pushbroom --out " + dir.path() + kSmall +
                        " --tilt-deg 20 --pos-error-m 0.05 --pos-error-deg 0.005"
                        " --detector-error-px 0.5 --node-spacing 50 --control-noise-m 0.1"
                        " --image-noise-px 0.25 --image-sigma-px 0.25 --height-m 1000 --relief-m 80"
                        " --survey-sigma-m 0.1");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  for (const char* f : {"camera_nominal.yaml",
                        "camera_truth.yaml",
                        "pos.csv",
                        "pos_truth.csv",
                        "observations.csv",
                        "points.csv",
                        "points_truth.csv",
                        "truth_detectors.csv",
                        "truth_trajectory.csv"})
    EXPECT_TRUE(std::filesystem::exists(dir.File(f))) << f;
  auto run = RunAerocal(Calibrate(
      dir.path(),
      "--out " + dir.File("result.json") + " --write-camera " + dir.File("calibrated.yaml") +
          " --lines " + dir.File("lines.csv") + " --plot " + dir.File("plot.svg") +
          " --node-spacing 50 --degree auto --max-degree 4 --degree-alpha 0.05"
          " --datum reference --reference -1 --pos-prior on"
          " --pos-sigma-m 0.05 --pos-sigma-deg 0.005 --sigma-px 0.25"
          " --min-per-segment 5"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json doc = aerocal::testing::ReadJson(dir.File("result.json"));
  for (const char* key : {"kind",
                          "sigma0",
                          "sigma0_px",
                          "redundancy",
                          "iterations",
                          "converged",
                          "valid",
                          "subcameras",
                          "detectors",
                          "trajectory",
                          "correlations",
                          "warnings",
                          "c_mm",
                          "c_sigma_mm"})
    EXPECT_TRUE(doc.contains(key)) << key;
  EXPECT_EQ(doc["kind"], "pushbroom");
  EXPECT_TRUE(doc["c_sigma_mm"].is_null()) << "c fixed: unknown sigma is null";
  EXPECT_EQ(doc["boresight"]["mode"], "fixed");
  EXPECT_TRUE(doc["boresight"]["sigma_deg"].is_null()) << "fixed: sigma null";
  EXPECT_EQ(doc["lever_arm"]["mode"], "fixed");
  EXPECT_TRUE(doc["lever_arm"]["sigma_m"].is_null()) << "fixed: sigma null";
  ASSERT_EQ(doc["subcameras"].size(), 3u);
  for (const json& s : doc["subcameras"]) {
    EXPECT_LT(s["rms_after_px"]["across"].get<double>(), 0.35);
    EXPECT_LT(s["rms_after_px"]["along"].get<double>(), 0.35);
    EXPECT_GT(s["rms_before_px"]["across"].get<double>(),
              s["rms_after_px"]["across"].get<double>());
    EXPECT_LE(s["degree_x"].get<int>(), 4);
  }
  EXPECT_EQ(doc["detectors"].size(), 180u);
  // The degree test ran from the start degree; a table's sigma is never below its fit's (a
  // reduced table: at least the start-degree fit's, line_degree_choice.h).
  EXPECT_TRUE(doc["degree_test"]["applied"].get<bool>());
  EXPECT_EQ(doc["degree_test"]["start_degree"], 4);
  EXPECT_DOUBLE_EQ(doc["degree_test"]["alpha"].get<double>(), 0.05);
  EXPECT_EQ(doc["degree_test"]["table_sigma"],
            doc["degree_test"]["reduced"].get<bool>() ? "selected" : "fit");
  for (const json& d : doc["detectors"])
    for (const char* axis : {"dx", "dy"})
      EXPECT_GE(d[std::string("sigma_") + axis + "_mm"].get<double>(),
                d[std::string("sigma_") + axis + "_fit_mm"].get<double>());
  const calib::LineCamera cam = calib::ReadLineCamera(dir.File("calibrated.yaml"));
  EXPECT_EQ(cam.calibration.size(), 3u);
  EXPECT_TRUE(std::filesystem::exists(dir.File("lines.csv")));

  // The plot: valid XML, per sub-camera and axis one group with one fitted curve over every
  // detector of the sub-camera, its sigma band, and (nearly) every observation as a dot.
  tinyxml2::XMLDocument svg;
  ASSERT_EQ(svg.LoadFile(dir.File("plot.svg").c_str()), tinyxml2::XML_SUCCESS) << svg.ErrorStr();
  const tinyxml2::XMLElement* root = svg.RootElement();
  ASSERT_NE(root, nullptr);
  EXPECT_STREQ(root->Name(), "svg");
  std::set<std::string> panels;
  for (const auto* g = root->FirstChildElement("g"); g; g = g->NextSiblingElement("g")) {
    ASSERT_TRUE(g->Attribute("data-subcamera") && g->Attribute("data-axis"));
    const std::string id = g->Attribute("data-subcamera"), axis = g->Attribute("data-axis");
    EXPECT_TRUE(panels.insert(id + "/" + axis).second) << id << " " << axis;
    int fits = 0, bands = 0, dots = 0;
    for (const auto* e = g->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const char* cls = e->Attribute("class");
      if (std::string(e->Name()) == "polyline" && cls && std::string(cls) == "fit") {
        ++fits;
        const std::string points = e->Attribute("points");
        EXPECT_EQ(std::count(points.begin(), points.end(), ','), 60) << "one vertex per detector";
      }
      if (std::string(e->Name()) == "polygon" && cls && std::string(cls) == "band") ++bands;
      if (std::string(e->Name()) == "circle") ++dots;
    }
    EXPECT_EQ(fits, 1) << id << " " << axis;
    EXPECT_EQ(bands, 1) << id << " " << axis;
    for (const json& s : doc["subcameras"]) {
      if (s["id"] == id) {
        EXPECT_GE(dots, 0.95 * s["n"].get<int>()) << id << " " << axis;
      }
    }
  }
  EXPECT_EQ(panels.size(), 6u);

  // The default datum: the null space as configured, in result.json (POS priors on: none).
  {
    auto gauge = RunAerocal(Calibrate(dir.path(), "--out " + dir.File("gauge.json")));
    ASSERT_EQ(gauge.exit_code, 0) << gauge.output;
    EXPECT_NE(gauge.output.find("datum gauge: rank defect 0 without it, 0 constraints"),
              std::string::npos)
        << gauge.output;
    const json d = aerocal::testing::ReadJson(dir.File("gauge.json"))["datum"];
    for (const char* key : {"mode",
                            "rank_defect",
                            "threshold",
                            "smallest_relative_eigenvalues",
                            "n_constraints",
                            "subcamera",
                            "blocks",
                            "gauge_directions",
                            "parameters_in_null_space"})
      EXPECT_TRUE(d.contains(key)) << key;
    EXPECT_EQ(d["mode"], "gauge");
    EXPECT_EQ(d["rank_defect"], 0);
    EXPECT_EQ(d["n_constraints"], 0);
  }
  // A fixed degree and c free: the scale is named; exit 3 only when ill-posed beyond 0.999.
  auto c_run =
      RunAerocal(Calibrate(dir.path(), "--out " + dir.File("c.json") + " --free-c --degree 3"));
  ASSERT_TRUE(c_run.exit_code == 0 || c_run.exit_code == 3) << c_run.output;
  EXPECT_NE(c_run.output.find("correlation scale_vs_c"), std::string::npos) << c_run.output;

  // No datum, no POS prior: ill-posed by name, exit 3, no camera written.
  auto bad = RunAerocal(Calibrate(dir.path(),
                                  "--out " + dir.File("none.json") +
                                      " --datum none --pos-prior off --write-camera " +
                                      dir.File("none.yaml")));
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
  EXPECT_TRUE(bad.output.find("warning: offset_vs_pitch") != std::string::npos ||
              bad.output.find("warning: undetermined") != std::string::npos)
      << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("none.yaml")));
  EXPECT_EQ(aerocal::testing::ReadJson(dir.File("none.json"))["valid"], false);
}

// A boresight misalignment and a lever arm planted in the camera file (off the flight's by (0.05,
// -0.05, 0.3) deg and (0.5, -0.5, 0.5) m; the flight of the library test). `--boresight free`
// (lever arm at its truth) and `--lever-arm free` (boresight at its truth) bring each back within 3
// sigma of the truth, more than 3 sigma away from the planted value (not the vertical lever arm:
// sigma ~1 m, nearly a scale on this narrow strip), and write it into the updated camera; both
// free: within 3 sigma, the lever arm across track vs the boresight roll named; weighted: sigmas
// below the prior's.
TEST(PushbroomCommands, BoresightAndLeverArmFromAPlantedMisalignment) {
  TempDir dir;
  ASSERT_EQ(RunAerocal("simulate --pushbroom --out " + dir.path() +
                       " --detectors 120 --lines 800 --control 700 --seed 7")
                .exit_code,
            0);
  const calib::LineCamera nominal = calib::ReadLineCamera(dir.File("camera_nominal.yaml"));
  const calib::LineCamera truth = calib::ReadLineCamera(dir.File("camera_truth.yaml"));
  const double delta_deg[3] = {0.05, -0.05, 0.3}, delta_m[3] = {0.5, -0.5, 0.5};
  double truth_deg[3], truth_m[3], planted_deg[3], planted_m[3];
  for (int a = 0; a < 3; ++a) {
    truth_deg[a] = truth.mount_rad[a] * 180.0 / M_PI;
    truth_m[a] = truth.lever_arm_m[a];
    planted_deg[a] = truth_deg[a] + delta_deg[a];
    planted_m[a] = truth_m[a] + delta_m[a];
  }
  const std::string inputs = " --pos " + dir.File("pos.csv") + " --observations " +
                             dir.File("observations.csv") + " --points " + dir.File("points.csv");
  auto calibrate =
      [&](bool boresight, bool lever, const std::string& name, const std::string& extra) {
        calib::LineCamera camera = nominal;
        if (boresight)
          camera.mount_rad =
              Eigen::Vector3d(planted_deg[0], planted_deg[1], planted_deg[2]) * (M_PI / 180.0);
        if (lever) camera.lever_arm_m = Eigen::Vector3d(planted_m[0], planted_m[1], planted_m[2]);
        calib::WriteLineCamera(dir.File(name + ".yaml"), camera);
        return RunAerocal("pushbroom calibrate --camera " + dir.File(name + ".yaml") + inputs +
                          " --out " + dir.File(name + ".json") + " --write-camera " +
                          dir.File(name + "_out.yaml") + extra +
                          " --datum reference");  // the default automatic degree (the
        // datum does not depend on it); a free boresight is a rotation of the table, a gauge the
        // default datum names as not determinable (module README "Datum"): the earlier Legendre
        // datum, which the simulated reference satisfies, explicitly
      };
  for (const bool boresight : {true, false}) {
    const std::string name = boresight ? "boresight" : "lever";
    auto run = calibrate(
        boresight, !boresight, name, boresight ? " --boresight free" : " --lever-arm free");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::printf("%s\n", run.output.c_str());
    EXPECT_NE(run.output.find(boresight ? "boresight (free): omega" : "lever arm (free): x"),
              std::string::npos)
        << run.output;
    const json doc = aerocal::testing::ReadJson(dir.File(name + ".json"));
    const json& entry = boresight ? doc["boresight"] : doc["lever_arm"];
    ASSERT_EQ(entry["mode"], "free");
    const calib::LineCamera out = calib::ReadLineCamera(dir.File(name + "_out.yaml"));
    for (int a = 0; a < 3; ++a) {
      const double v = entry[boresight ? "opk_deg" : "xyz_m"][a],
                   s = entry[boresight ? "sigma_deg" : "sigma_m"][a];
      EXPECT_LT(std::abs(v - (boresight ? truth_deg[a] : truth_m[a])), 3 * s) << name << " " << a;
      if (boresight || a < 2) {
        EXPECT_GT(std::abs(v - (boresight ? planted_deg[a] : planted_m[a])), 3 * s)
            << name << " " << a;
      }
      EXPECT_NEAR(boresight ? out.mount_rad[a] * 180.0 / M_PI : out.lever_arm_m[a], v, 1e-9);
    }
  }
  auto both = calibrate(true, true, "both", " --boresight free --lever-arm free");
  ASSERT_TRUE(both.exit_code == 0 || both.exit_code == 3) << both.output;
  EXPECT_NE(both.output.find("lever_arm_x_vs_boresight"), std::string::npos) << both.output;
  const json doc = aerocal::testing::ReadJson(dir.File("both.json"));
  for (const char* name : {"boresight_roll_vs_offset",
                           "boresight_pitch_vs_offset",
                           "boresight_phi_vs_attitude",
                           "lever_arm_y_vs_position",
                           "lever_arm_x_vs_boresight"})
    EXPECT_TRUE(doc["correlations"].contains(name)) << name;
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(std::abs(doc["boresight"]["opk_deg"][a].get<double>() - truth_deg[a]),
              3 * doc["boresight"]["sigma_deg"][a].get<double>())
        << a;
    EXPECT_LT(std::abs(doc["lever_arm"]["xyz_m"][a].get<double>() - truth_m[a]),
              3 * doc["lever_arm"]["sigma_m"][a].get<double>())
        << a;
  }

  auto weighted = calibrate(true,
                            true,
                            "weighted",
                            " --boresight weighted --boresight-sigma-deg 0.01"
                            " --lever-arm weighted --lever-arm-sigma-m 0.05");
  ASSERT_TRUE(weighted.exit_code == 0 || weighted.exit_code == 3) << weighted.output;
  const json w = aerocal::testing::ReadJson(dir.File("weighted.json"));
  ASSERT_EQ(w["boresight"]["mode"], "weighted");
  const double cap = std::max(1.0, w["sigma0"].get<double>()) * (1 + 1e-9);  // sigma0 sqrt(Q)
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(w["boresight"]["sigma_deg"][a].get<double>(), 0.01 * cap);
    EXPECT_LE(w["lever_arm"]["sigma_m"][a].get<double>(), 0.05 * cap);
  }
}

TEST(PushbroomCommands, BadInputIsRefusedWithFileAndLine) {
  TempDir dir;
  ASSERT_EQ(RunAerocal("simulate --pushbroom --out " + dir.path() + kSmall).exit_code, 0);
  // An observation beyond the POS lines.
  std::string obs = ReadTextFile(dir.File("observations.csv"));
  obs += "strip,c1,10,99999,0.25\n";
  const int bad_line = int(std::count(obs.begin(), obs.end(), '\n'));
  std::ofstream(dir.File("obs_bad.csv")) << obs;
  auto run =
      RunAerocal("pushbroom calibrate --camera " + dir.File("camera_nominal.yaml") + " --pos " +
                 dir.File("pos.csv") + " --observations " + dir.File("obs_bad.csv") + " --points " +
                 dir.File("points.csv") + " --out " + dir.File("r.json"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("obs_bad.csv:" + std::to_string(bad_line) + ": row (scan line) 99999"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
  // A plot below a file (not a folder): refused by option name, nothing written.
  run = RunAerocal(Calibrate(
      dir.path(), "--out " + dir.File("r.json") + " --plot " + dir.File("points.csv/p.svg")));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--plot"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
  // A bad option.
  run = RunAerocal(Calibrate(dir.path(), "--out " + dir.File("r.json") + " --degree 7"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--degree"), std::string::npos) << run.output;
  // Bad datum options: named, exit 2, nothing written.
  for (const char* bad : {" --datum minimal", " --gauge-threshold 0.5"}) {
    run = RunAerocal(Calibrate(dir.path(), "--out " + dir.File("r.json") + bad));
    EXPECT_EQ(run.exit_code, 2) << bad << run.output;
    EXPECT_NE(run.output.find(std::string(bad).substr(1, std::string(bad).find(' ', 1) - 1)),
              std::string::npos)
        << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
  }
  // A bad camera file line.
  std::ofstream(dir.File("cam.yaml")) << "line:\n  detectors: 180\n  pitch_mm: 0.01\n  c: -3\n";
  run = RunAerocal("pushbroom calibrate --camera " + dir.File("cam.yaml") + " --pos " +
                   dir.File("pos.csv") + " --observations " + dir.File("observations.csv") +
                   " --points " + dir.File("points.csv") + " --out " + dir.File("r.json"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("cam.yaml:4: line.c must be within"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
}

// The patent writes the line along the camera's y axis (CONVENTIONS "Line (pushbroom) cameras"):
// a camera file with `line_axis: y` is converted at the reader, so the same camera written either
// way calibrates identically, and the updated camera is written back in the file's convention.
TEST(PushbroomCommands, PatentLineAxisGivesTheSameCalibration) {
  TempDir dir;
  ASSERT_EQ(RunAerocal("simulate --pushbroom --out " + dir.path() + kSmall).exit_code, 0);
  calib::LineCamera camera = calib::ReadLineCamera(dir.File("camera_nominal.yaml"));
  camera.file_line_along_y = true;
  calib::WriteLineCamera(dir.File("camera_y.yaml"), camera);
  const std::string text = ReadTextFile(dir.File("camera_y.yaml"));
  EXPECT_NE(text.find("line_axis: y"), std::string::npos) << text;
  // The file holds the other frame: the virtual camera's mount (a boresight of 0.1 / -0.05 / 0.2
  // deg in ours) turns by 90 deg in kappa.
  const YAML::Node y_file = YAML::LoadFile(dir.File("camera_y.yaml"));
  EXPECT_NEAR(std::abs(y_file["line"]["mount_deg"][2].as<double>()), 90.0, 0.5) << text;
  const calib::LineCamera back = calib::ReadLineCamera(dir.File("camera_y.yaml"));
  EXPECT_TRUE(back.file_line_along_y);
  for (int i = 0; i < camera.detectors; ++i)
    EXPECT_LT((back.DetectorPosition(i) - camera.DetectorPosition(i)).norm(), 1e-12) << i;
  EXPECT_LT((back.mount_rad - camera.mount_rad).norm(), 1e-12);
  for (size_t k = 0; k < camera.subcameras.size(); ++k)
    EXPECT_LT((back.subcameras[k].mount_rad - camera.subcameras[k].mount_rad).norm(), 1e-12) << k;

  const auto calibrate = [&](const std::string& cam, const std::string& name) {
    return RunAerocal("pushbroom calibrate --camera " + cam + " --pos " + dir.File("pos.csv") +
                      " --observations " + dir.File("observations.csv") + " --points " +
                      dir.File("points.csv") + " --out " + dir.File(name + ".json") +
                      " --write-camera " + dir.File(name + ".yaml"));
  };
  const auto x_run = calibrate(dir.File("camera_nominal.yaml"), "x");
  const auto y_run = calibrate(dir.File("camera_y.yaml"), "y");
  ASSERT_EQ(x_run.exit_code, 0) << x_run.output;
  ASSERT_EQ(y_run.exit_code, 0) << y_run.output;
  const json x = aerocal::testing::ReadJson(dir.File("x.json"));
  const json y = aerocal::testing::ReadJson(dir.File("y.json"));
  ASSERT_EQ(x["detectors"].size(), y["detectors"].size());
  for (size_t i = 0; i < x["detectors"].size(); ++i)
    for (const char* key : {"dx_mm", "dy_mm", "sigma_dx_mm", "sigma_dy_mm"})
      EXPECT_NEAR(x["detectors"][i][key].get<double>(), y["detectors"][i][key].get<double>(), 1e-10)
          << i << " " << key;
  EXPECT_NEAR(x["sigma0"].get<double>(), y["sigma0"].get<double>(), 1e-9);
  // The updated camera comes back in the file's convention and means the same detectors.
  EXPECT_NE(ReadTextFile(dir.File("y.yaml")).find("line_axis: y"), std::string::npos);
  const calib::LineCamera x_cam = calib::ReadLineCamera(dir.File("x.yaml"));
  const calib::LineCamera y_cam = calib::ReadLineCamera(dir.File("y.yaml"));
  for (int i = 0; i < x_cam.detectors; ++i)
    EXPECT_LT((x_cam.DetectorPosition(i) - y_cam.DetectorPosition(i)).norm(), 1e-10) << i;
  // A bad value: FILE:LINE and the key.
  std::ofstream(dir.File("bad.yaml"))
      << "line:\n  detectors: 180\n  pitch_mm: 0.01\n  c: 3\n  line_axis: z\n";
  const auto bad =
      RunAerocal("pushbroom calibrate --camera " + dir.File("bad.yaml") + " --pos " +
                 dir.File("pos.csv") + " --observations " + dir.File("observations.csv") +
                 " --points " + dir.File("points.csv") + " --out " + dir.File("r.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("bad.yaml:5: line.line_axis must be x or y"), std::string::npos)
      << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
}

TEST(PushbroomCommands, ExampleCameraOfConfigsIsRead) {
  const calib::LineCamera cam =
      calib::ReadLineCamera(std::string(AEROCAL_CONFIGS_DIR) + "/line_camera_three.yaml");
  EXPECT_EQ(cam.subcameras.size(), 3u);
  EXPECT_EQ(cam.detectors, 3000);
}

}  // namespace
}  // namespace aerocal::triangulation
