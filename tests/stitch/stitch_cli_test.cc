// The 'aerocal stitch' and 'aerocal resample' commands on the example cameras in configs/:
// exit codes, FORMATS.md result keys, refusal messages, the virtual TIFF and its metadata, and a
// camera file in another model (OpenCV's) giving the same result and pixels.
#include "calib/camera/camera_io.h"
#include "calib/camera/convert_camera.h"
#include "calib/core/result_file.h"
#include "stitch/resample/tiff_raster.h"
#include "stitch/simulation/stitch_simulator.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <random>

namespace aerocal::stitch {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;

struct Example {
  std::string file, base;
  std::vector<std::string> base_ids;
};

const Example kExamples[] = {{"camera_2x3.yaml", "II,V", {"II", "V"}},
                             {"camera_12ccd.yaml", "VI,VII", {"VI", "VII"}},
                             {"camera_3x3.yaml", "V", {"V"}}};

// Writes `frames` simulated frames of a misplaced copy of `camera` to PATH; returns the truth.
calib::Camera WriteFrames(const calib::Camera& camera,
                          const std::vector<std::string>& base,
                          int frames,
                          const std::string& path) {
  std::mt19937_64 rng(42);
  MisplacementOptions misplacement;
  misplacement.shear = 2e-4;
  const calib::Camera truth = MakeMisplacedCamera(camera, base, misplacement, rng);
  FrameSimulationOptions options;
  options.ties_per_frame = 400;
  std::vector<StitchObservation> rows;
  for (int f = 1; f <= frames; ++f) {
    const auto frame = SimulateFrame(truth, "F" + std::to_string(f), options, rng);
    rows.insert(rows.end(), frame.begin(), frame.end());
  }
  WriteStitchObservations(path, rows);
  return truth;
}

using aerocal::testing::ReadJson;

TEST(StitchCommand, AdjustsEveryExampleCameraWithTheFormatsKeys) {
  for (const Example& example : kExamples) {
    SCOPED_TRACE(example.file);
    TempDir tmp;
    const std::string camera_path = std::string(AEROCAL_CONFIGS_DIR) + "/" + example.file;
    const calib::Camera camera = calib::ReadCamera(camera_path);
    WriteFrames(camera, example.base_ids, 1, tmp.File("obs.csv"));
    const auto run = RunAerocal("stitch --camera " + camera_path + " --obs " + tmp.File("obs.csv") +
                                " --base " + example.base + " --out " + tmp.File("r.json"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const auto doc = ReadJson(tmp.File("r.json"));
    for (const char* key : {"kind",
                            "sigma0",
                            "sigma0_px",
                            "redundancy",
                            "iterations",
                            "converged",
                            "model",
                            "subimages",
                            "residuals",
                            "rejected",
                            "model_choice",
                            "max_corner_sigma_px"})
      EXPECT_TRUE(doc.contains(key)) << key;
    EXPECT_EQ(doc["kind"], "stitch");
    EXPECT_NEAR(doc["sigma0_px"].get<double>(), 0.1, 0.015);
    EXPECT_EQ(doc["subimages"].size(), camera.subimages.size());
    for (const auto& s : doc["subimages"]) {
      for (const char* key : {"id", "model", "params", "sigma", "corners"})
        EXPECT_TRUE(s.contains(key)) << key;
      EXPECT_EQ(s["params"].size(), s["sigma"].size());
      EXPECT_EQ(s["corners"].size(), 4u);
    }
    EXPECT_EQ(doc["model_choice"]["table"].size(), 4u);
  }
}

TEST(StitchCommand, BatchWritesFramesAndStability) {
  TempDir tmp;
  const std::string camera_path = std::string(AEROCAL_CONFIGS_DIR) + "/camera_2x3.yaml";
  WriteFrames(calib::ReadCamera(camera_path), {"II", "V"}, 4, tmp.File("obs.csv"));
  const auto run = RunAerocal("stitch --camera " + camera_path + " --obs " + tmp.File("obs.csv") +
                              " --base II,V --model affine --out " + tmp.File("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto doc = ReadJson(tmp.File("r.json"));
  ASSERT_EQ(doc["frames"].size(), 4u);
  EXPECT_EQ(doc["model"], "affine");
  EXPECT_TRUE(doc["stability"].contains("mean_sigma0_px"));
  EXPECT_TRUE(doc["stability"].contains("std_sigma0_px"));
  EXPECT_NEAR(doc["stability"]["mean_sigma0_px"].get<double>(), 0.1, 0.01);
  for (const auto& f : doc["frames"])
    for (const char* key :
         {"frame", "sigma0", "sigma0_px", "redundancy", "iterations", "converged", "subimages"})
      EXPECT_TRUE(f.contains(key)) << key;
}

// `camera` in OpenCV's model (the exact conversion of its pinhole), its sub-images kept.
calib::Camera InOpenCvModel(const calib::Camera& camera) {
  return camera.WithModelCamera(
      calib::ConvertCamera(camera.AsModelCamera(), calib::CameraModelId::kOpenCv).camera);
}

// The stitching reads no interior term: a camera file in another registered model with the same
// sub-images gives the same result, number for number.
TEST(StitchCommand, ACameraInAnotherModelGivesTheSameResult) {
  TempDir tmp;
  const std::string camera_path = std::string(AEROCAL_CONFIGS_DIR) + "/camera_2x3.yaml";
  const calib::Camera camera = calib::ReadCamera(camera_path);
  calib::WriteCamera(tmp.File("opencv.yaml"), InOpenCvModel(camera));
  WriteFrames(camera, {"II", "V"}, 1, tmp.File("obs.csv"));
  const std::string args = " --obs " + tmp.File("obs.csv") + " --base II,V --out ";
  const auto ours = RunAerocal("stitch --camera " + camera_path + args + tmp.File("bf.json"));
  ASSERT_EQ(ours.exit_code, 0) << ours.output;
  const auto other =
      RunAerocal("stitch --camera " + tmp.File("opencv.yaml") + args + tmp.File("cv.json"));
  ASSERT_EQ(other.exit_code, 0) << other.output;
  EXPECT_EQ(ReadJson(tmp.File("cv.json")), ReadJson(tmp.File("bf.json")));
}

TEST(StitchCommand, RefusesBadInputWithExitTwoAndNothingWritten) {
  TempDir tmp;
  const std::string camera_path = std::string(AEROCAL_CONFIGS_DIR) + "/camera_2x3.yaml";
  {
    std::ofstream out(tmp.File("bad.csv"));
    out << "frame,point,subimage,u,v,sigma_px\n1,t1,I,10,20,0.1\n1,t1,II,abc,20,0.1\n";
  }
  auto run = RunAerocal("stitch --camera " + camera_path + " --obs " + tmp.File("bad.csv") +
                        " --out " + tmp.File("r.json"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("bad.csv:3"), std::string::npos) << run.output;
  {
    std::ofstream out(tmp.File("unknown.csv"));
    out << "frame,point,subimage,u,v\n1,t1,I,10,20\n1,t1,XX,10,20\n";
  }
  run = RunAerocal("stitch --camera " + camera_path + " --obs " + tmp.File("unknown.csv") +
                   " --out " + tmp.File("r.json"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("sub-image 'XX'"), std::string::npos) << run.output;
  // Two ties on sub-image I, nothing on the others: the affine model is refused, naming I.
  {
    std::ofstream out(tmp.File("few.csv"));
    out << "frame,point,subimage,u,v\n";
    for (int i = 0; i < 2; ++i)
      out << "1,t" << i << ",I,4700," << 100 + 1000 * i << "\n1,t" << i << ",II,100,"
          << 100 + 1000 * i << "\n";
  }
  run = RunAerocal("stitch --camera " + camera_path + " --obs " + tmp.File("few.csv") +
                   " --base II,V --model affine --out " + tmp.File("r.json"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find("sub-image I:"), std::string::npos) << run.output;
  run = RunAerocal("stitch --camera " + camera_path + " --obs " + tmp.File("few.csv") +
                   " --base II,XX --out " + tmp.File("r.json"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_FALSE(std::ifstream(tmp.File("r.json")).good());
}

TEST(ResampleCommand, WritesTheVirtualTiffWithTheMappingInTheMetadata) {
  TempDir tmp;
  // A small 2 x 2 camera so that the command runs in a moment.
  const std::string yaml = R"(name: small
pixel_size_mm: 0.009
format_px: [400, 300]
interior: {c: 50}
subimages:
  - {id: I, format_px: [210, 160], model: affine, params: [1, 0, 0, 0, 1, 0]}
  - {id: II, format_px: [210, 160], model: affine, params: [1, 0, 190, 0, 1, 0]}
  - {id: III, format_px: [210, 160], model: affine, params: [1, 0, 0, 0, 1, 140]}
  - {id: IV, format_px: [210, 160], model: affine, params: [1, 0, 190, 0, 1, 140]}
)";
  std::ofstream(tmp.File("camera.yaml")) << yaml;
  const calib::Camera camera = calib::ReadCamera(tmp.File("camera.yaml"));
  // Stitch result: the nominal mappings, II shifted left by half a pixel.
  nlohmann::json result = {{"kind", "stitch"},
                           {"schema_version", aerocal::kResultSchemaVersion},
                           {"subimages", nlohmann::json::array()}};
  for (const auto& s : camera.subimages) {
    std::vector<double> p = s.params;
    if (s.id == "II") p[2] -= 0.5;
    result["subimages"].push_back({{"id", s.id}, {"model", "affine"}, {"params", p}});
  }
  std::ofstream(tmp.File("r.json")) << result.dump();
  // 16-bit sub-images of a constant grey value per image; overlaps average them.
  std::string images;
  for (size_t k = 0; k < camera.subimages.size(); ++k) {
    const auto& s = camera.subimages[k];
    MemoryRaster raster({s.width_px, s.height_px, 1, 16});
    for (int v = 0; v < s.height_px; ++v)
      for (int u = 0; u < s.width_px; ++u) raster.Set(u, v, 0, 1000.0 * (k + 1));
    const std::string path = tmp.File(s.id + ".tif");
    TiffWriter writer(path, raster.Info(), {});
    writer.WriteRows(0, s.height_px, raster.bytes().data());
    writer.Commit();
    images += (k ? "," : "") + s.id + "=" + path;
  }
  const auto run = RunAerocal("resample --camera " + tmp.File("camera.yaml") + " --mapping " +
                              tmp.File("r.json") + " --images " + images + " --out " +
                              tmp.File("v.tif") + " --fill 7 --interp bicubic");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto source = OpenTiff(tmp.File("v.tif"));
  ASSERT_EQ(source->Info().width, 400);
  ASSERT_EQ(source->Info().bits, 16);
  MemoryRaster v(source->Info());
  source->ReadWindow(0, 0, 400, 300, v.bytes().data());
  EXPECT_EQ(v.At(10, 10), 1000);    // I only
  EXPECT_EQ(v.At(200, 10), 1500);   // I and II
  EXPECT_EQ(v.At(200, 150), 2500);  // all four
  EXPECT_EQ(v.At(390, 290), 4000);  // IV only
  EXPECT_EQ(v.At(399, 10), 7);      // II moved by -0.5 px: the last column is not covered
  const std::string description = ReadTiffDescription(tmp.File("v.tif"));
  EXPECT_NE(description.find("II affine 210 160 1 0 189.5 0 1 0"), std::string::npos)
      << description;
  // In strips of 7 rows and as BigTIFF: the same pixels.
  const auto strips =
      RunAerocal("resample --camera " + tmp.File("camera.yaml") + " --mapping " +
                 tmp.File("r.json") + " --images " + images + " --out " + tmp.File("b.tif") +
                 " --fill 7 --interp bicubic --strip-rows 7 --bigtiff");
  ASSERT_EQ(strips.exit_code, 0) << strips.output;
  EXPECT_TRUE(IsBigTiff(tmp.File("b.tif")));
  EXPECT_FALSE(IsBigTiff(tmp.File("v.tif")));
  MemoryRaster b(source->Info());
  OpenTiff(tmp.File("b.tif"))->ReadWindow(0, 0, 400, 300, b.bytes().data());
  EXPECT_EQ(b.bytes(), v.bytes());
  // The camera in OpenCV's model (the resampling reads no interior term): the same pixels.
  calib::WriteCamera(tmp.File("opencv.yaml"), InOpenCvModel(camera));
  const auto other = RunAerocal("resample --camera " + tmp.File("opencv.yaml") + " --mapping " +
                                tmp.File("r.json") + " --images " + images + " --out " +
                                tmp.File("cv.tif") + " --fill 7 --interp bicubic");
  ASSERT_EQ(other.exit_code, 0) << other.output;
  MemoryRaster cv(source->Info());
  OpenTiff(tmp.File("cv.tif"))->ReadWindow(0, 0, 400, 300, cv.bytes().data());
  EXPECT_EQ(cv.bytes(), v.bytes());
  // A sub-image without an image is refused.
  const auto bad = RunAerocal("resample --camera " + tmp.File("camera.yaml") + " --mapping " +
                              tmp.File("r.json") + " --images I=" + tmp.File("I.tif") + " --out " +
                              tmp.File("w.tif"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("no image for sub-image II"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace aerocal::stitch
