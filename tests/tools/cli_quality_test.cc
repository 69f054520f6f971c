// `aerocal quality mtf` on exactly rendered slanted edges (tests/support/rendered_targets.h) written
// as 8-bit PNG and 16-bit TIFF files: MTF50 against the analytic value, the units through the pixel
// size and the GSD, the per-axis combination of repeated edges, and bad options (exit 2 naming the
// option, nothing written).
#include <cmath>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "stitch/image_io/image_io.h"
#include "tests/support/rendered_targets.h"
#include "tests/support/test_support.h"

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
  image.rightCols(128) = testing::RenderEdge(128, 128, 187.0 * kDeg, kS, 40.0 * scale, 210.0 * scale);
  std::normal_distribution<double> normal(0.0, noise);
  for (int i = 0; i < image.size(); ++i) image.data()[i] += static_cast<float>(normal(*rng));
  return image;
}

double Analytic(double slant_deg) {
  return testing::FirstCrossing([&](double f) { return testing::RenderedEdgeMtf(f, kS, slant_deg * kDeg); }, 0.5);
}

TEST(CliQuality, MtfOfEightAndSixteenBitEdgesWithGroundUnits) {
  testing::TempDir dir("aerocal_cli_quality");
  std::mt19937_64 rng(36);
  stitch::WriteGrayImage(dir.File("edges8.png"), TwoEdges(1.0, 1.0, &rng), 8);
  stitch::WriteGrayImage(dir.File("edges16.tif"), TwoEdges(256.0, 256.0, &rng), 16);
  for (const std::string name : {"edges8.png", "edges16.tif"}) {
    const auto run = RunAerocal("quality mtf --image " + dir.File(name) +
                                " --roi 0,0,128,128 --roi 128,0,128,128 --pixel-mm 0.006 --gsd-m 0.08 "
                                "--gsd-sigma-m 0.001 --flight-axis y --out " + dir.File("r.json"));
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

TEST(CliQuality, BadOptionsExitTwoNamingTheOption) {
  testing::TempDir dir("aerocal_cli_quality_bad");
  std::mt19937_64 rng(1);
  stitch::WriteGrayImage(dir.File("e.png"), TwoEdges(1.0, 1.0, &rng), 8);
  const std::string base = "quality mtf --image " + dir.File("e.png") + " --out " + dir.File("r.json");
  const std::pair<std::string, std::string> cases[] = {
      {" --roi 0,0,128", "--roi"},            // three numbers
      {" --roi 200,0,128,128", "--roi"},      // leaves the image
      {" --roi 0,0,128,128 --gamma 0", "--gamma"},
      {" --roi 0,0,128,128 --oversampling 1", "--oversampling"},
      {" --roi 0,0,128,128 --flight-axis z", "--flight-axis"},
      {" --roi 0,0,128,128 --gsd-sigma-m 0.01", "--gsd-sigma-m"},
  };
  for (const auto& [options, name] : cases) {
    const auto run = RunAerocal(base + options);
    EXPECT_EQ(run.exit_code, 2) << options << "\n" << run.output;
    EXPECT_NE(run.output.find(name), std::string::npos) << options << "\n" << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir.File("r.json"))) << options;
  }
  // A region of a flat part of the image: no edge, exit 2 naming the region.
  stitch::WriteGrayImage(dir.File("flat.png"), stitch::GrayImage::Constant(64, 64, 100.0f), 8);
  const auto flat = RunAerocal("quality mtf --image " + dir.File("flat.png") + " --roi 0,0,64,64 --out " +
                               dir.File("r.json"));
  EXPECT_EQ(flat.exit_code, 2) << flat.output;
  EXPECT_NE(flat.output.find("--roi 0,0,64,64"), std::string::npos) << flat.output;
}

}  // namespace
}  // namespace aerocal
