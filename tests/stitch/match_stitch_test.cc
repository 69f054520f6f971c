// Acceptance of `aerocal match` on real pixels (issue: tie points to a tenth of a pixel): the
// Boruszyn scene (match_test_scene.h) written as 8-bit TIFF sub-images plus the NOMINAL camera
// file; `aerocal match` (the predicted search, LSM on and off; the descriptor search with SIFT and
// Foerstner), the maker reference points measured in the
// sub-images through the true mappings (noise 0.05 px, their camera-file sigma), then the affine
// stitching adjustment: sigma0 <= 0.12 px, every sub-image corner within 3 predicted sigmas and
// 0.25 px of its true virtual position. Also: byte-identical output for identical inputs,
// appending frames, a camera file in another model, and bad images named in the error.
#include "calib/camera/camera_io.h"
#include "calib/camera/convert_camera.h"
#include "calib/core/atomic_file.h"
#include "stitch/adjustment/stitch_adjustment.h"
#include "tests/stitch/match_test_scene.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

namespace aerocal::stitch {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;

class MatchStitch : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!testing::BoruszynScene()) return;
    const auto& scene = *testing::BoruszynScene();
    dir_ = new TempDir("aerocal_match");
    calib::WriteCamera(dir_->File("camera.yaml"), scene.nominal);
    images_arg_ = new std::string;
    for (std::size_t k = 0; k < scene.images.size(); ++k) {
      const std::string& id = scene.nominal.subimages[k].id;
      WriteGrayImage(dir_->File(id + ".tif"), scene.images[k]);
      *images_arg_ += (k ? "," : "") + id + "=" + dir_->File(id + ".tif");
    }
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete images_arg_;
  }
  void SetUp() override {
    if (!testing::BoruszynScene()) GTEST_SKIP() << "shared data odm_boruszyn_kap_frames absent";
  }
  static std::string Match(const std::string& out, const std::string& extra = "") {
    return "match --camera " + dir_->File("camera.yaml") + " --frame 4880 --images " +
           *images_arg_ + " --out " + out + " " + extra;
  }
  static TempDir* dir_;
  static std::string* images_arg_;
};
TempDir* MatchStitch::dir_ = nullptr;
std::string* MatchStitch::images_arg_ = nullptr;

// The ties of `obs` plus the reference points measured through the true mappings.
std::string WithReferences(const std::string& obs, const std::string& out) {
  const auto& scene = *testing::BoruszynScene();
  std::vector<StitchObservation> rows = ReadStitchObservations(obs, 0.1);
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (const calib::ReferencePoint& p : scene.nominal.reference_points) {
    const auto& sub = scene.truth.subimages[scene.truth.SubimageIndex(p.subimage)];
    const Eigen::Vector2d uv = sub.SubFromVirtual({p.U, p.V});
    rows.push_back(
        {"4880", p.id, p.subimage, uv.x() + noise(rng), uv.y() + noise(rng), p.sigma_px});
  }
  WriteStitchObservations(out, rows);
  return out;
}

struct CornerCheck {
  double sigma0_px = 0, max_error_px = 0, max_error_in_sigmas = 0;
};

CornerCheck AdjustAndCompare(const std::string& obs) {
  const auto& scene = *testing::BoruszynScene();
  const auto frames = GroupByFrame(scene.nominal, ReadStitchObservations(obs, 0.1), obs);
  EXPECT_EQ(frames.size(), 1u);
  const FrameAdjustment adj =
      AdjustFrame(scene.nominal, frames.at(0), calib::MappingModel::kAffine, StitchOptions{});
  EXPECT_TRUE(adj.converged);
  EXPECT_TRUE(adj.covariance_ok);
  CornerCheck check;
  check.sigma0_px = adj.sigma0_px;
  for (std::size_t k = 0; k < adj.subimages.size(); ++k) {
    for (const CornerPrecision& c : adj.subimages[k].corners) {
      const Eigen::Vector2d d = c.virtual_px - scene.truth.subimages[k].VirtualFromSub(c.uv);
      check.max_error_px = std::max(check.max_error_px, d.norm());
      check.max_error_in_sigmas = std::max({check.max_error_in_sigmas,
                                            std::abs(d.x()) / c.sigma_U_px,
                                            std::abs(d.y()) / c.sigma_V_px});
    }
  }
  std::printf("  rejected %zu, redundancy %d\n", adj.rejected.size(), adj.redundancy);
  return check;
}

// The acceptance bounds of matched ties: sigma0 <= 0.12 px, every corner within 0.25 px and 3
// of its predicted sigmas of the truth.
void ExpectMeetsTheAcceptance(const CornerCheck& check, const char* what) {
  std::printf("%s: sigma0 %.3f px, corners max error %.3f px = %.2f sigma\n",
              what,
              check.sigma0_px,
              check.max_error_px,
              check.max_error_in_sigmas);
  EXPECT_LE(check.sigma0_px, 0.12) << what;
  EXPECT_LE(check.max_error_px, 0.25) << what;
  EXPECT_LE(check.max_error_in_sigmas, 3.0) << what;
}

TEST_F(MatchStitch, MatchThenAffineStitchRecoversTheTrueCorners) {
  const std::string on = dir_->File("on.csv"), off = dir_->File("off.csv");
  ASSERT_EQ(RunAerocal(Match(on)).exit_code, 0);
  ASSERT_EQ(RunAerocal(Match(off, "--lsm off")).exit_code, 0);
  const CornerCheck without = AdjustAndCompare(WithReferences(off, dir_->File("off_ref.csv")));
  std::printf("LSM off: sigma0 %.3f px, corners max error %.3f px = %.2f sigma\n",
              without.sigma0_px,
              without.max_error_px,
              without.max_error_in_sigmas);
  ExpectMeetsTheAcceptance(AdjustAndCompare(WithReferences(on, dir_->File("on_ref.csv"))),
                           "LSM on ");

  // The stitch command reads the file as written.
  const auto result =
      RunAerocal("stitch --camera " + dir_->File("camera.yaml") + " --obs " +
                 dir_->File("on_ref.csv") + " --model affine --out " + dir_->File("r.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json doc = aerocal::testing::ReadJson(dir_->File("r.json"));
  EXPECT_LE(doc.at("sigma0_px").get<double>(), 0.12);

  // Same inputs, same file, byte for byte.
  ASSERT_EQ(RunAerocal(Match(dir_->File("again.csv"))).exit_code, 0);
  EXPECT_EQ(ReadTextFile(on), ReadTextFile(dir_->File("again.csv")));
}

// The descriptor search (the fallback where the nominal mappings are not known to the margin),
// with either detector.
TEST_F(MatchStitch, TheDescriptorSearchMeetsTheSameBoundsAndRepeats) {
  for (const std::string detector : {"sift", "foerstner"}) {
    const std::string a = dir_->File(detector + ".csv"), b = dir_->File(detector + "_again.csv");
    const std::string options = "--search descriptors --detector " + detector;
    ASSERT_EQ(RunAerocal(Match(a, options)).exit_code, 0);
    ExpectMeetsTheAcceptance(AdjustAndCompare(WithReferences(a, dir_->File(detector + "_ref.csv"))),
                             (detector + ", LSM on").c_str());
    ASSERT_EQ(RunAerocal(Match(b, options)).exit_code, 0);
    EXPECT_EQ(ReadTextFile(a), ReadTextFile(b));
  }
}

TEST_F(MatchStitch, FlightListAppendsFramesAndRefusesDuplicates) {
  const auto& scene = *testing::BoruszynScene();
  std::string list = "frame,subimage,image\n";
  for (const auto& s : scene.nominal.subimages) list += "b," + s.id + "," + s.id + ".tif\n";
  WriteFileAtomically(dir_->File("list.csv"), list);
  const std::string out = dir_->File("flight.csv");
  // Frame "a" first, then frame "b" of the list appended.
  ASSERT_EQ(RunAerocal("match --camera " + dir_->File("camera.yaml") + " --frame a --images " +
                       *images_arg_ + " --out " + out)
                .exit_code,
            0);
  const std::string before = ReadTextFile(out);
  const std::string list_run = "match --camera " + dir_->File("camera.yaml") + " --list " +
                               dir_->File("list.csv") + " --append --out " + out;
  ASSERT_EQ(RunAerocal(list_run).exit_code, 0);
  const auto rows = ReadStitchObservations(out, 0.1);
  std::set<std::string> frames;
  for (const auto& r : rows) frames.insert(r.frame);
  EXPECT_EQ(frames, (std::set<std::string>{"a", "b"}));
  EXPECT_EQ(ReadTextFile(out).substr(0, before.size()), before);  // old rows kept as they were
  // Appending frame b again is refused and leaves the file alone.
  const std::string after = ReadTextFile(out);
  const auto again = RunAerocal(list_run);
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.output.find("frame b is already in the file"), std::string::npos) << again.output;
  EXPECT_EQ(ReadTextFile(out), after);
}

// Matching reads no interior term: the camera file in OpenCV's model (its sub-images kept) gives
// the same observations, byte for byte.
TEST_F(MatchStitch, ACameraInAnotherModelGivesTheSameObservations) {
  const calib::Camera camera = calib::ReadCamera(dir_->File("camera.yaml"));
  calib::WriteCamera(
      dir_->File("camera_opencv.yaml"),
      camera.WithModelCamera(
          calib::ConvertCamera(camera.AsModelCamera(), calib::CameraModelId::kOpenCv).camera));
  const std::string options = " --frame 4880 --images " + *images_arg_ + " --lsm off --out ";
  const std::string a = dir_->File("model_bf.csv"), b = dir_->File("model_cv.csv");
  ASSERT_EQ(RunAerocal("match --camera " + dir_->File("camera.yaml") + options + a).exit_code, 0);
  const auto other = RunAerocal("match --camera " + dir_->File("camera_opencv.yaml") + options + b);
  ASSERT_EQ(other.exit_code, 0) << other.output;
  EXPECT_EQ(ReadTextFile(b), ReadTextFile(a));
}

TEST_F(MatchStitch, BadImagesAreNamedAndNothingIsWritten) {
  const std::string cam = dir_->File("camera.yaml"), out = dir_->File("bad.csv");
  auto images_with = [&](const std::string& second) {
    std::string arg = *images_arg_;
    const auto from = arg.find(",II="), to = arg.find(",III=");
    return arg.substr(0, from) + ",II=" + second + arg.substr(to);
  };
  // Missing file.
  auto r = RunAerocal("match --camera " + cam + " --frame 1 --images " +
                      images_with(dir_->File("nothing.tif")) + " --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(dir_->File("nothing.tif") + ": image file not found"), std::string::npos)
      << r.output;
  // Not an image.
  WriteFileAtomically(dir_->File("text.tif"), "not an image\n");
  r = RunAerocal("match --camera " + cam + " --frame 1 --images " +
                 images_with(dir_->File("text.tif")) + " --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(dir_->File("text.tif") + ": cannot decode image"), std::string::npos)
      << r.output;
  // Wrong format for the camera file.
  WriteGrayImage(dir_->File("small.tif"), GrayImage::Constant(10, 20, 9.0f));
  r = RunAerocal("match --camera " + cam + " --frame 1 --images " +
                 images_with(dir_->File("small.tif")) + " --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(dir_->File("small.tif") + ": image is 20 x 10 px, but sub-image II"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::ifstream(out).good());
}

// OpenCV's imgcodecs (with GDAL, ~140 shared libraries) is no longer linked: the program starts
// without it, and the first image read or written loads it through the module (image_codecs.h).
TEST(ImageCodecs, TheProgramStartsWithoutThemAndTheFirstImageLoadsThem) {
  const auto libraries = aerocal::testing::RunCommand("ldd " + aerocal::testing::AerocalBinary());
  ASSERT_EQ(libraries.exit_code, 0) << libraries.output;
  EXPECT_EQ(libraries.output.find("libopencv_imgcodecs"), std::string::npos) << libraries.output;
  EXPECT_EQ(libraries.output.find("libgdal"), std::string::npos) << libraries.output;

  TempDir dir("aerocal_codecs");
  GrayImage image(3, 4);
  for (int i = 0; i < image.size(); ++i) image.data()[i] = static_cast<float>(1000 * i + 7);
  WriteGrayImage(dir.File("ramp.png"), image, 16);
  const GrayImage back = ReadGrayImage(dir.File("ramp.png"));
  ASSERT_EQ(back.rows(), 3);
  ASSERT_EQ(back.cols(), 4);
  for (int i = 0; i < image.size(); ++i) EXPECT_EQ(back.data()[i], image.data()[i]) << i;
  std::ifstream maps("/proc/self/maps");
  const std::string mapped((std::istreambuf_iterator<char>(maps)),
                           std::istreambuf_iterator<char>());
  EXPECT_NE(mapped.find("libaerocal_image_codecs.so"), std::string::npos);
  EXPECT_NE(mapped.find("libopencv_imgcodecs"), std::string::npos);
}

}  // namespace
}  // namespace aerocal::stitch
