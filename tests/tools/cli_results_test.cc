// Result documents of the commands (calib/core/result_file.h): every command's result carries
// `kind` and `schema_version` (and the camera model's parameter table where a camera is in it),
// and the readers of results refuse another kind or version with `FILE: what`, exit 2, nothing
// written. `aerocal flight`, `rig stitch` and `pushbroom control` are checked the same way in their
// own CLI tests (cli_flight, cli_rig_stitch, pushbroom_images): they are too long to run twice.
#include "calib/core/result_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace aerocal {
namespace {

using nlohmann::json;
using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

const std::string kRig = std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens.yaml";
const std::string kLimits = std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens_limits.yaml";

void Write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// The header every result carries; `model` is the camera model expected in `camera_model`
// (empty: the document holds no camera of the registry).
void ExpectHeader(const json& doc, const std::string& kind, const std::string& model = "") {
  EXPECT_EQ(doc.value("kind", ""), kind);
  EXPECT_EQ(doc.value("schema_version", -1), kResultSchemaVersion) << kind;
  if (model.empty()) return;
  ASSERT_TRUE(doc.contains("camera_model")) << kind;
  EXPECT_EQ(doc["camera_model"]["name"], model) << kind;
  EXPECT_FALSE(doc["camera_model"]["parameters"].empty()) << kind;
  for (const json& p : doc["camera_model"]["parameters"])
    for (const char* key : {"name", "unit", "group"})
      EXPECT_TRUE(p.contains(key)) << kind << " " << key;
}

class ResultDocuments : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("aerocal_cli_results");
    const auto flight = RunAerocal("simulate --out " + dir_->File("flight"));
    ASSERT_EQ(flight.exit_code, 0) << flight.output;
    const auto field = RunAerocal("simulate --test-field --groups 2 --images-per-group 4 --out " +
                                  dir_->File("tf"));
    ASSERT_EQ(field.exit_code, 0) << field.output;
    const auto cal =
        RunAerocal("calibrate --camera " + dir_->File("tf/camera_nominal.yaml") +
                   " --observations " + dir_->File("tf/observations.csv") + " --points " +
                   dir_->File("tf/points.csv") + " --out " + dir_->File("cal.json"));
    ASSERT_LE(cal.exit_code, 3) << cal.output;  // 3: written, the group stability may disagree
  }
  static void TearDownTestSuite() { delete dir_; }
  static TempDir* dir_;
};
TempDir* ResultDocuments::dir_ = nullptr;

TEST_F(ResultDocuments, EveryCommandWritesKindAndSchemaVersion) {
  const std::string sim = dir_->File("flight");
  auto r =
      RunAerocal("adjust --project " + sim + "/project.yaml --out " + dir_->File("adjust.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectHeader(ReadJson(dir_->File("adjust.json")), "adjust", "brown_fraser_10");

  // calibrate: an adjustment result (kind "adjust") with command and calibration sections.
  const json cal = ReadJson(dir_->File("cal.json"));
  ExpectHeader(cal, "adjust", "brown_fraser_10");
  EXPECT_EQ(cal["command"], "calibrate");

  r = RunAerocal("certificate --result " + dir_->File("cal.json") + " --no-render --out " +
                 dir_->File("cert"));
  ASSERT_LE(r.exit_code, 3) << r.output;
  ExpectHeader(ReadJson(dir_->File("cert/certificate.json")), "certificate", "brown_fraser_10");

  r = RunAerocal("stitch --camera " + sim + "/camera_nominal.yaml --obs " + sim +
                 "/stitch_obs.csv --base III,IV --out " + dir_->File("stitch.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectHeader(ReadJson(dir_->File("stitch.json")), "stitch");

  r = RunAerocal("camera convert --from aerocal --to opencv " + sim + "/camera_nominal.yaml " +
                 dir_->File("cv.yml") + " --report " + dir_->File("convert.json"));
  ASSERT_LE(r.exit_code, 3) << r.output;  // 3: a fit beyond --max-residual-px, still reported
  const json convert = ReadJson(dir_->File("convert.json"));
  ExpectHeader(convert, "camera_conversion", "opencv");
  EXPECT_EQ(convert["source_camera_model"]["name"], "brown_fraser_10");

  r = RunAerocal("rig design --camera " + kRig + " --grid-cells 50 --out " +
                 dir_->File("design.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json design = ReadJson(dir_->File("design.json"));
  ExpectHeader(design, "rig_design");
  EXPECT_EQ(design["camera_models"].size(), 2u);

  r = RunAerocal("rig error-analysis --camera " + kRig + " --limits " + kLimits +
                 " --samples 0 --no-plots --out " + dir_->File("error.json"));
  ASSERT_LE(r.exit_code, 3) << r.output;
  const json error = ReadJson(dir_->File("error.json"));
  ExpectHeader(error, "rig_error_analysis");
  EXPECT_EQ(error["camera_models"].size(), 2u);

  const std::string pb = dir_->File("pb");
  r = RunAerocal("simulate --pushbroom --out " + pb +
                 " --detectors 60 --lines 400 --control 300 --seed 3");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunAerocal("pushbroom calibrate --camera " + pb + "/camera_nominal.yaml --pos " + pb +
                 "/pos.csv --observations " + pb + "/observations.csv --points " + pb +
                 "/points.csv --out " + dir_->File("pushbroom.json"));
  ASSERT_LE(r.exit_code, 3) << r.output;
  ExpectHeader(ReadJson(dir_->File("pushbroom.json")), "pushbroom");
}

// A reader of results refuses another kind and another schema_version by name, exit 2, and
// writes nothing: the certificate (of `calibrate`) and resample's stitch result (--mapping).
TEST_F(ResultDocuments, ReadersRefuseAnotherKindOrVersion) {
  json doc = ReadJson(dir_->File("cal.json"));
  doc["schema_version"] = kResultSchemaVersion + 1;
  Write(dir_->File("v2.json"), doc.dump());
  auto r = RunAerocal("certificate --result " + dir_->File("v2.json") + " --no-render --out " +
                      dir_->File("cert_v2"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("v2.json: schema_version is 2, expected 1 (kind \"adjust\")"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("cert_v2/certificate.json")));

  doc.erase("schema_version");
  Write(dir_->File("v0.json"), doc.dump());
  r = RunAerocal("certificate --result " + dir_->File("v0.json") + " --no-render --out " +
                 dir_->File("cert_v0"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("v0.json: schema_version is null, expected 1"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("cert_v0/certificate.json")));

  // A stitch result where a calibrate result is expected, and the other way round.
  json stitch = {
      {"kind", "stitch"}, {"schema_version", kResultSchemaVersion}, {"subimages", json::array()}};
  Write(dir_->File("stitch_kind.json"), stitch.dump());
  r = RunAerocal("certificate --result " + dir_->File("stitch_kind.json") + " --no-render --out " +
                 dir_->File("cert_stitch"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(
      r.output.find("stitch_kind.json: not a result of `aerocal calibrate` (kind is \"stitch\", "
                    "expected \"adjust\" or \"flight\")"),
      std::string::npos)
      << r.output;
  const std::string sim = dir_->File("flight");
  r = RunAerocal("resample --camera " + sim + "/camera_nominal.yaml --mapping " +
                 dir_->File("cal.json") + " --images I=a.tif --out " + dir_->File("v.tif"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(
      r.output.find("cal.json: not a result of `aerocal stitch` (kind is \"adjust\", expected "
                    "\"stitch\")"),
      std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("v.tif")));
}

}  // namespace
}  // namespace aerocal
