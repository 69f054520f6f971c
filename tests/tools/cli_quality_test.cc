// `aerocal quality mtf` on exactly rendered slanted edges (tests/support/rendered_targets.h)
// written as 8-bit PNG and 16-bit TIFF files: MTF50 against the analytic value, the units through
// the pixel size and the GSD, the per-axis combination of repeated edges, and bad options (exit 2
// naming the option, nothing written). `aerocal quality bars` on rendered bar groups and `aerocal
// quality star` on a rendered Siemens star: the limiting frequency.
#include "calib/core/atomic_file.h"
#include "stitch/image_io/image_io.h"
#include "tests/support/rendered_targets.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <random>

namespace aerocal {
namespace {

using testing::RunAerocal;
constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kS = 1.2;  // px, Gaussian PSF

// Two 128 x 128 edges side by side, both near-vertical (MTF along x), slanted 4 and 7 deg, with
// noise; then rounded to the bit depth by the writer.
stitch::GrayImage TwoEdges(double scale, double noise, std::mt19937_64* rng) {
  stitch::GrayImage image(128, 256);
  image.leftCols(128) = testing::RenderEdge(128, 128, 4.0 * kDeg, kS, 40.0 * scale, 210.0 * scale);
  image.rightCols(128) =
      testing::RenderEdge(128, 128, 187.0 * kDeg, kS, 40.0 * scale, 210.0 * scale);
  std::normal_distribution<double> normal(0.0, noise);
  for (int i = 0; i < image.size(); ++i) image.data()[i] += static_cast<float>(normal(*rng));
  return image;
}

double Analytic(double slant_deg) {
  return testing::FirstCrossing(
      [&](double f) { return testing::RenderedEdgeMtf(f, kS, slant_deg * kDeg); }, 0.5);
}

TEST(CliQuality, MtfOfEightAndSixteenBitEdgesWithGroundUnits) {
  testing::TempDir dir("aerocal_cli_quality");
  std::mt19937_64 rng(36);
  stitch::WriteGrayImage(dir.File("edges8.png"), TwoEdges(1.0, 1.0, &rng), 8);
  stitch::WriteGrayImage(dir.File("edges16.tif"), TwoEdges(256.0, 256.0, &rng), 16);
  for (const std::string name : {"edges8.png", "edges16.tif"}) {
    const auto run =
        RunAerocal("quality mtf --image " + dir.File(name) +
                   " --roi 0,0,128,128 --roi 128,0,128,128 --pixel-size-mm 0.006 --gsd-m 0.08 "
                   "--gsd-sigma-m 0.001 --flight-axis y --out " +
                   dir.File("r.json"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json doc = testing::ReadJson(dir.File("r.json"));
    EXPECT_EQ(doc["kind"], "quality_mtf");
    ASSERT_EQ(doc["edges"].size(), 2u);
    const double slants[2] = {4.0, 7.0};
    for (int i = 0; i < 2; ++i) {
      const auto& e = doc["edges"][i];
      EXPECT_EQ(e["axis"], "x");
      EXPECT_EQ(e["direction"], "across_track");  // flight along y: an MTF along x is across track
      EXPECT_NEAR(std::abs(e["angle_deg"].get<double>()), slants[i], 0.05) << name;
      const double f50 = e["mtf50_cy_px"].get<double>();
      EXPECT_NEAR(f50 / Analytic(slants[i]), 1.0, 0.02) << name << " edge " << i;
      EXPECT_NEAR(e["mtf50_lp_per_mm"].get<double>(), f50 / 0.006, 1e-9);
      EXPECT_NEAR(e["mtf50_resolved_distance_m"].get<double>(), 0.08 / (2.0 * f50), 1e-12);
      EXPECT_GT(e["mtf50_expanded_cy_px"].get<double>(), 0.0);
      EXPECT_EQ(e["curve"]["frequency_cy_px"].size(), e["curve"]["mtf"].size());
    }
    // Two edges along x: combined with a type-A part.
    ASSERT_TRUE(doc["axes"].contains("x")) << doc["axes"].dump();
    EXPECT_EQ(doc["axes"]["x"]["count"], 2);
    EXPECT_GT(doc["axes"]["x"]["type_a_u_cy_px"].get<double>(), 0.0);
    EXPECT_FALSE(doc["axes"].contains("y"));
  }
}

// --virtual --roi: with --image-origin each region gets its place in the virtual image (the file's
// origin plus the region's centre pixel, the report's MTF50 map); without it none (a file of
// patches from several exposures has no one place).
TEST(CliQuality, ImageOriginPlacesAVirtualRegionInTheFormat) {
  testing::TempDir dir("aerocal_cli_quality_origin");
  std::mt19937_64 rng(37);
  stitch::WriteGrayImage(dir.File("window.png"), TwoEdges(1.0, 1.0, &rng), 8);
  const std::string base =
      "quality mtf --image " + dir.File("window.png") + " --virtual --roi 128,0,128,128";
  auto run = RunAerocal(base + " --image-origin 1000,2000 --out " + dir.File("o.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json placed = testing::ReadJson(dir.File("o.json"))["edges"][0];
  ASSERT_TRUE(placed.contains("position_virtual_px")) << placed.dump();
  EXPECT_EQ(placed["position_virtual_px"], nlohmann::json({1000 + 128 + 63.5, 2000 + 63.5}));
  run = RunAerocal(base + " --out " + dir.File("n.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_FALSE(testing::ReadJson(dir.File("n.json"))["edges"][0].contains("position_virtual_px"));
}

TEST(CliQuality, BadOptionsExitTwoNamingTheOption) {
  testing::TempDir dir("aerocal_cli_quality_bad");
  std::mt19937_64 rng(1);
  stitch::WriteGrayImage(dir.File("e.png"), TwoEdges(1.0, 1.0, &rng), 8);
  const std::string base =
      "quality mtf --image " + dir.File("e.png") + " --out " + dir.File("r.json");
  const std::pair<std::string, std::string> cases[] = {
      {" --roi 0,0,128", "--roi"},        // three numbers
      {" --roi 200,0,128,128", "--roi"},  // leaves the image
      {" --roi 0,0,128,128 --gamma 0", "--gamma"},
      {" --roi 0,0,128,128 --oversampling 1", "--oversampling"},
      {" --roi 0,0,128,128 --flight-axis z", "--flight-axis"},
      {" --roi 0,0,128,128 --gsd-sigma-m 0.01", "--gsd-sigma-m"},
      {" --roi 0,0,128,128 --sub-image I --virtual", "--virtual"},  // a raw or the virtual image
      {"", "--roi or --targets"},                                   // no region at all
      {" --targets t.csv", "--targets needs --camera"},             // no orientation
      {" --targets t.csv --camera c.yaml --orientation r.json --image-id 1 --sub-image I "
       "--frame 3",
       "--frame needs --mapping"},  // a frame of the stitch result
      {" --roi 0,0,128,128 --mapping m.json", "--mapping, --frame and --virtual-image need"},
      {" --roi 0,0,128,128 --sub-image I --frame 7", "--mapping, --frame and --virtual-image need"},
      {" --targets t.csv --camera c.yaml --orientation r.json --image-id 1 --virtual-image v.tif",
       "--virtual-image need --targets and --sub-image"},
      {" --targets t.csv --camera c.yaml --orientation r.json --image-id 1 --sub-image I "
       "--mapping m.json --virtual-image v.tif --virtual-origin 0,2.5",
       "--virtual-origin"},
      {" --targets t.csv --camera c.yaml --orientation r.json --image-id 1 --image-origin 1.5,0",
       "--image-origin"},
      {" --targets t.csv --camera c.yaml --orientation r.json --image-id 1 --image-origin 1e12,0",
       "--image-origin"},  // would overflow the integer origin
      {" --roi 0,0,128,128 --target-length-px 8", "--target-length-px"},
      {" --roi 0,0,128,128 --target-half-width-px 2", "--target-half-width-px"},
  };
  for (const auto& [options, name] : cases) {
    const auto run = RunAerocal(base + options);
    EXPECT_EQ(run.exit_code, 2) << options << "\n" << run.output;
    EXPECT_NE(run.output.find(name), std::string::npos) << options << "\n" << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("r.json"))) << options;
  }
  // A region of a flat part of the image: no edge, exit 2 naming the region.
  stitch::WriteGrayImage(dir.File("flat.png"), stitch::GrayImage::Constant(64, 64, 100.0f), 8);
  const auto flat = RunAerocal("quality mtf --image " + dir.File("flat.png") +
                               " --roi 0,0,64,64 --out " + dir.File("r.json"));
  EXPECT_EQ(flat.exit_code, 2) << flat.output;
  EXPECT_NE(flat.output.find("--roi 0,0,64,64"), std::string::npos) << flat.output;
}

// Bar groups of vertical bars (blur s px), one block of 24 rows each, then a bright and a dark
// block (16 bit), written to `path`; returns the --group options.
const double kBarFrequencies[] = {0.1, 0.14, 0.2, 0.28, 0.4};
std::string WriteBarTarget(const std::string& path, double s) {
  stitch::GrayImage image(7 * 24, 160);
  std::string groups;
  for (int g = 0; g < 5; ++g) {
    for (int c = 0; c < 160; ++c)
      image.block(g * 24, c, 24, 1)
          .setConstant(static_cast<float>(
              256.0 *
              (30.0 + 190.0 * testing::BarPixelFraction(c, 1.0 / kBarFrequencies[g], 0.3, s))));
    groups += " --group " + std::to_string(kBarFrequencies[g]) + ",4," +
              std::to_string(g * 24 + 2) + ",152,20,x";
  }
  image.block(5 * 24, 0, 24, 160).setConstant(256.0f * 220.0f);
  image.block(6 * 24, 0, 24, 160).setConstant(256.0f * 30.0f);
  stitch::WriteGrayImage(path, image, 16);
  return groups;
}
const std::string kBarReferences = " --bright 4,122,152,20 --dark 4,146,152,20";

TEST(CliQuality, BarsGiveTheLimitingFrequencyAndGroundUnits) {
  testing::TempDir dir("aerocal_cli_quality_bars");
  const double s = 1.0;
  const std::string base =
      "quality bars --image " + dir.File("bars.tif") + WriteBarTarget(dir.File("bars.tif"), s);
  const auto run = RunAerocal(base + kBarReferences + " --pixel-size-mm 0.005 --gsd-m 0.1 --out " +
                              dir.File("bars.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json doc = testing::ReadJson(dir.File("bars.json"));
  EXPECT_EQ(doc["kind"], "quality_bars");
  ASSERT_EQ(doc["groups"].size(), 5u);
  const double limit = doc["limiting_frequency_cy_px"].get<double>();
  const double truth =
      testing::FirstCrossing([&](double f) { return testing::RenderedBarContrast(f, s); }, 0.1);
  // Within one step of this target (0.28 -> 0.4, a factor 1.43).
  EXPECT_LE(std::abs(std::log(limit / truth)), std::log(0.4 / 0.28)) << limit << " vs " << truth;
  EXPECT_TRUE(doc["limit_in_range"].get<bool>());
  EXPECT_NEAR(doc["limiting_lp_per_mm"].get<double>(), limit / 0.005, 1e-9);
  EXPECT_NEAR(doc["limiting_resolved_distance_m"].get<double>(), 0.1 / (2.0 * limit), 1e-12);
  EXPECT_FALSE(doc.contains("limiting_resolved_distance_expanded_m"));  // no U for bars yet
  EXPECT_NEAR(doc["groups"][0]["contrast_transfer"].get<double>(),
              testing::RenderedBarContrast(0.1, s),
              0.03);
  const std::pair<std::string, std::string> bad[] = {
      {" --bright 4,122,152,20 --dark 4,146,152,20 --group 0.7,4,2,152,20", "--group"},
      {" --bright 4,122,152 --dark 4,146,152,20", "--bright"},
      {" --bright 4,122,152,20 --dark 4,146,152,20 --threshold 1.5", "--threshold"},
      {" --bright 4,146,152,20 --dark 4,122,152,20", "--bright"},  // swapped: no contrast
  };
  for (const auto& [options, name] : bad) {
    const auto r = RunAerocal(base + options + " --out " + dir.File("bad.json"));
    EXPECT_EQ(r.exit_code, 2) << options << "\n" << r.output;
    EXPECT_NE(r.output.find(name), std::string::npos) << options << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("bad.json"))) << options;
  }
}

// The certificate of a test-field calibration with the "dynamic image resolution" section from a
// quality mtf and a quality bars result: the values copied, rendered into the HTML and the PDF.
// A Siemens star of 24 cycles (blur s px) in a 420 x 420 8-bit PNG at `path`; returns its options.
std::string WriteStar(const std::string& path, double s) {
  stitch::WriteGrayImage(
      path, testing::RenderSiemensStar(420, 24, {209.5, 209.5}, 0.4, s, 30.0, 220.0), 8);
  return " --centre 209.5,209.5 --cycles 24 --outer-radius-px 200";
}

TEST(CliQuality, StarGivesTheLimitingFrequencyAndGroundUnits) {
  testing::TempDir dir("aerocal_cli_quality_star");
  const double s = 1.2;
  const std::string base =
      "quality star --image " + dir.File("star.png") + WriteStar(dir.File("star.png"), s);
  const auto run =
      RunAerocal(base + " --pixel-size-mm 0.005 --gsd-m 0.1 --out " + dir.File("star.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json doc = testing::ReadJson(dir.File("star.json"));
  EXPECT_EQ(doc["kind"], "quality_star");
  const double limit = doc["limiting_frequency_cy_px"].get<double>();
  const double truth =
      testing::FirstCrossing([&](double f) { return testing::RenderedStarTransfer(f, s); }, 0.1);
  EXPECT_LE(std::abs(std::log(limit / truth)), std::log(doc["step_ratio"].get<double>()))
      << limit << " vs " << truth;
  EXPECT_TRUE(doc["limit_in_range"].get<bool>());
  EXPECT_NEAR(doc["limiting_lp_per_mm"].get<double>(), limit / 0.005, 1e-9);
  EXPECT_NEAR(doc["limiting_resolved_distance_m"].get<double>(), 0.1 / (2.0 * limit), 1e-12);
  EXPECT_NEAR(
      doc["limiting_radius_px"].get<double>(), 24 / (2 * 3.14159265358979323846 * limit), 1e-9);
  // --inner-radius-px and --steps-per-octave: the rings stop at the inner radius, a step 2^(1/6)
  // apart.
  const auto coarse =
      RunAerocal(base + " --inner-radius-px 30 --steps-per-octave 6 --gamma 1 --out " +
                 dir.File("coarse.json"));
  ASSERT_EQ(coarse.exit_code, 0) << coarse.output;
  const nlohmann::json c = testing::ReadJson(dir.File("coarse.json"));
  EXPECT_NEAR(c["step_ratio"].get<double>(), std::pow(2.0, 1.0 / 6.0), 1e-12);
  EXPECT_GE(c["rings"].back()["radius_px"].get<double>(), 30.0 * (1 - 1e-9));
  EXPECT_LT(c["rings"].back()["radius_px"].get<double>(), 30.0 * std::pow(2.0, 1.0 / 6.0));
  const std::pair<std::string, std::string> bad[] = {
      {" --centre 209.5 --cycles 24 --outer-radius-px 200", "--centre"},
      {" --centre 209.5,209.5 --cycles 24 --outer-radius-px 260",
       "--outer-radius-px"},  // leaves the image
      {" --centre 209.5,209.5 --cycles 2 --outer-radius-px 200", "--cycles"},
      {" --centre 209.5,209.5 --cycles 24 --outer-radius-px 200 --threshold 1.5", "--threshold"},
  };
  for (const auto& [options, name] : bad) {
    const auto r = RunAerocal("quality star --image " + dir.File("star.png") + options + " --out " +
                              dir.File("bad.json"));
    EXPECT_EQ(r.exit_code, 2) << options << "\n" << r.output;
    EXPECT_NE(r.output.find(name), std::string::npos) << options << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("bad.json"))) << options;
  }
}

TEST(CliQuality, CertificateGainsTheDynamicImageResolutionSection) {
  testing::TempDir dir("aerocal_cli_quality_cert");
  ASSERT_EQ(
      RunAerocal("simulate --test-field --groups 2 --images-per-group 4 --out " + dir.File("tf"))
          .exit_code,
      0);
  const auto cal = RunAerocal("calibrate --camera " + dir.File("tf/camera_nominal.yaml") +
                              " --observations " + dir.File("tf/observations.csv") + " --points " +
                              dir.File("tf/points.csv") + " --out " + dir.File("cal.json"));
  ASSERT_LE(cal.exit_code, 3) << cal.output;  // 3: written, the group stability may disagree
  std::mt19937_64 rng(12);
  stitch::WriteGrayImage(dir.File("edges.png"), TwoEdges(1.0, 1.0, &rng), 8);
  ASSERT_EQ(
      RunAerocal("quality mtf --image " + dir.File("edges.png") +
                 " --roi 0,0,128,128 --roi 128,0,128,128 --flight-axis y --gsd-m 0.05 --out " +
                 dir.File("q.json"))
          .exit_code,
      0);
  const std::string groups = WriteBarTarget(dir.File("bars.tif"), 1.0);
  ASSERT_EQ(RunAerocal("quality bars --image " + dir.File("bars.tif") + groups + kBarReferences +
                       " --gsd-m 0.05 --out " + dir.File("bars.json"))
                .exit_code,
            0);
  ASSERT_EQ(RunAerocal("quality star --image " + dir.File("star.png") +
                       WriteStar(dir.File("star.png"), 1.0) + " --gsd-m 0.05 --out " +
                       dir.File("star.json"))
                .exit_code,
            0);
  const auto run = RunAerocal("certificate --result " + dir.File("cal.json") + " --quality " +
                              dir.File("q.json") + " --quality " + dir.File("bars.json") +
                              " --quality " + dir.File("star.json") + " --out " + dir.File("cert"));
  ASSERT_LE(run.exit_code, 3) << run.output;
  const nlohmann::json cert = testing::ReadJson(dir.File("cert/certificate.json"));
  ASSERT_TRUE(cert.contains("dynamic_image_resolution")) << run.output;
  const auto& d = cert["dynamic_image_resolution"];
  const nlohmann::json q = testing::ReadJson(dir.File("q.json"));
  ASSERT_EQ(d["edges"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(d["edges"][i]["mtf50_cy_px"], q["edges"][i]["mtf50_cy_px"]);
    EXPECT_EQ(d["edges"][i]["mtf50_expanded_cy_px"], q["edges"][i]["mtf50_expanded_cy_px"]);
    EXPECT_EQ(d["edges"][i]["direction"], "across_track");
  }
  ASSERT_EQ(d["axes"].size(), 1u);
  EXPECT_EQ(d["axes"][0]["mtf50_cy_px"], q["axes"]["x"]["mtf50_cy_px"]);
  ASSERT_EQ(d["bars"].size(), 1u);
  EXPECT_EQ(d["bars"][0]["limiting_frequency_cy_px"],
            testing::ReadJson(dir.File("bars.json"))["limiting_frequency_cy_px"]);
  ASSERT_EQ(d["stars"].size(), 1u);
  EXPECT_EQ(d["stars"][0]["limiting_frequency_cy_px"],
            testing::ReadJson(dir.File("star.json"))["limiting_frequency_cy_px"]);
  const std::string html = ReadTextFile(dir.File("cert/certificate.html"));
  EXPECT_NE(html.find("9. Dynamic image resolution"), std::string::npos);
  EXPECT_NE(html.find("Siemens star"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir.File("cert/certificate.pdf")));
  // Another kind of result is refused, naming the file; nothing written.
  const auto bad = RunAerocal("certificate --result " + dir.File("cal.json") + " --quality " +
                              dir.File("cal.json") + " --no-render --out " + dir.File("cert2"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("not a result of `aerocal quality`"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("cert2/certificate.json")));
}

}  // namespace
}  // namespace aerocal
