// Result documents of the commands (calib/core/result_file.h): every command's result carries
// `kind` and `schema_version` (and the camera model's parameter table where a camera is in it),
// and the readers of results refuse another kind or version with `FILE: what`, exit 2, nothing
// written. Every result read through testing::ReadJson is checked against its kind's schema
// (docs/schema/<kind>.schema.json, testing::ExpectValidResult); EveryKindIsValidatedSomewhere
// lists, for each of kResultKinds, the file this suite writes or the CLI test that writes and
// validates it (`flight`, `rig stitch`, `pushbroom control`, `batch plan` and `quality` are too
// long or need images: their own CLI tests read their results through ReadJson).
#include "calib/core/result_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
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

// Each kind of kResultKinds is written and validated: here (the file) or in the CLI test named.
TEST_F(ResultDocuments, EveryKindIsValidatedSomewhere) {
  const std::map<std::string, std::string> here = {{"adjust", "adjust.json"},
                                                   {"certificate", "cert/certificate.json"},
                                                   {"stitch", "stitch.json"},
                                                   {"camera_conversion", "convert.json"},
                                                   {"rig_design", "design.json"},
                                                   {"rig_error_analysis", "error.json"},
                                                   {"pushbroom", "pushbroom.json"}};
  const std::map<std::string, std::string> elsewhere = {
      {"flight", "tools/cli_flight"},
      {"rig_stitch", "tools/cli_rig_stitch"},
      {"pushbroom_control", "triangulation/pushbroom_control_cli"},
      {"batch_manifest", "tools/cli_batch"},
      {"quality_mtf", "tools/cli_quality"},
      {"quality_bars", "tools/cli_quality"},
      {"quality_star", "tools/cli_quality"}};
  for (std::string_view k : kResultKinds) {
    const std::string kind(k);
    EXPECT_TRUE(std::filesystem::exists(testing::SchemaPath(kind))) << kind << ": no schema";
    if (elsewhere.count(kind)) continue;
    ASSERT_TRUE(here.count(kind)) << kind << ": no CLI test writes and validates it";
    const std::string path = dir_->File(here.at(kind));
    if (!std::filesystem::exists(path)) {  // EveryCommandWritesKindAndSchemaVersion writes it
      ADD_FAILURE() << path << " was not written";
      continue;
    }
    EXPECT_EQ(ReadJson(path)["kind"], kind);  // ReadJson validates it against the schema
  }
  // The calibrate form of an adjust result (command, calibration) validates too.
  testing::ExpectValidResult(dir_->File("cal.json"));
}

// `aerocal validate`: results against their schemas; a key the schema does not list, a value of
// the wrong type, another kind: exit 2 naming the file and the key path.
TEST_F(ResultDocuments, ValidateChecksResultsAgainstTheirSchemas) {
  auto r = RunAerocal("validate " + dir_->File("cal.json") + " " + dir_->File("adjust.json"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cal.json: valid"), std::string::npos) << r.output;

  json doc = ReadJson(dir_->File("cal.json"));
  doc["sigma0_pixels"] = 0.1;  // not a key of the adjust result
  Write(dir_->File("extra.json"), doc.dump());
  r = RunAerocal("validate " + dir_->File("extra.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("extra.json: sigma0_pixels: not allowed here (got 0.1)"),
            std::string::npos)
      << r.output;

  doc.erase("sigma0_pixels");
  doc["cameras"][0]["sigma"]["c"] = -0.001;  // a sigma is >= 0 or null
  Write(dir_->File("sigma.json"), doc.dump());
  r = RunAerocal("validate " + dir_->File("sigma.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("sigma.json: cameras[0].sigma.c: must be >= 0"), std::string::npos)
      << r.output;

  Write(dir_->File("other.json"),
        json({{"kind", "report"}, {"schema_version", kResultSchemaVersion}}).dump());
  r = RunAerocal("validate " + dir_->File("other.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("other.json: not a result of aerocal (kind is \"report\")"),
            std::string::npos)
      << r.output;
}

// A reader of results refuses another kind and another schema_version by name, exit 2, and
// writes nothing: the certificate (of `calibrate`) and resample's stitch result (--mapping).
TEST_F(ResultDocuments, ReadersRefuseAnotherKindOrVersion) {
  // A file of version 1 (before the findings of docs/schema/CHANGES.md) and of a later version.
  json doc = ReadJson(dir_->File("cal.json"));
  for (const int version : {1, kResultSchemaVersion + 1}) {
    doc["schema_version"] = version;
    const std::string name = "v" + std::to_string(version);
    Write(dir_->File(name + ".json"), doc.dump());
    const auto r = RunAerocal("certificate --result " + dir_->File(name + ".json") +
                              " --no-render --out " + dir_->File("cert_" + name));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(
        r.output.find(name + ".json: schema_version is " + std::to_string(version) + ", expected " +
                      std::to_string(kResultSchemaVersion) + " (kind \"adjust\")"),
        std::string::npos)
        << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_->File("cert_" + name + "/certificate.json")));
  }

  doc.erase("schema_version");
  Write(dir_->File("v0.json"), doc.dump());
  auto r = RunAerocal("certificate --result " + dir_->File("v0.json") + " --no-render --out " +
                      dir_->File("cert_v0"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("v0.json: schema_version is null, expected " +
                          std::to_string(kResultSchemaVersion)),
            std::string::npos)
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
