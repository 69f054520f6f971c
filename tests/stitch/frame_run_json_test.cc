// A frame's stitching run survives JSON to the last bit (stitch/io/frame_run_json.h): what
// `aerocal batch` hands from a unit to the merge must give the single process's numbers.
#include "stitch/io/frame_run_json.h"

#include "calib/core/error.h"
#include "stitch/io/stitch_result_json.h"
#include "tests/stitch/simulated_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace aerocal::stitch {
namespace {

TEST(FrameRunJson, RoundTripKeepsEveryBitAndTheBatchResult) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 2e-4, 31);
  const auto frames = testing::SimulateFrames(camera, 3, 300, 32);
  BatchOptions options;
  options.stitch.base_ids = camera.base;
  std::vector<FrameRun> back;
  for (const auto& frame : frames) {
    const FrameRun run = StitchFrame(camera.nominal, frame, options);  // --model auto: a choice
    ASSERT_TRUE(run.choice.has_value());
    const nlohmann::json once = FrameRunToJson(run);
    const FrameRun read = FrameRunFromJson(nlohmann::json::parse(once.dump()), "run.json");
    EXPECT_EQ(FrameRunToJson(read).dump(), once.dump());
    EXPECT_EQ(read.adjustment.sigma0, run.adjustment.sigma0);  // bits, not a tolerance
    EXPECT_EQ(read.adjustment.subimages[0].covariance, run.adjustment.subimages[0].covariance);
    back.push_back(read);
  }
  // The batch of the runs read back is the batch of the frames adjusted in this process.
  const BatchResult direct = RunStitchBatch(camera.nominal, frames, options, nullptr);
  EXPECT_EQ(StitchResultToJson(CollectBatch(back, options), options).dump(),
            StitchResultToJson(direct, options).dump());
}

TEST(FrameRunJson, NonFiniteNumbersTravelAsText) {
  FrameRun run;
  run.adjustment.sigma0 = std::numeric_limits<double>::quiet_NaN();
  run.adjustment.vtpv = std::numeric_limits<double>::infinity();
  run.adjustment.sigma0_px = -std::numeric_limits<double>::infinity();
  const nlohmann::json j = FrameRunToJson(run);
  EXPECT_EQ(j["adjustment"]["sigma0"], "nan");
  const FrameRun read = FrameRunFromJson(nlohmann::json::parse(j.dump()), "run.json");
  EXPECT_TRUE(std::isnan(read.adjustment.sigma0));
  EXPECT_EQ(read.adjustment.vtpv, std::numeric_limits<double>::infinity());
  EXPECT_EQ(read.adjustment.sigma0_px, -std::numeric_limits<double>::infinity());
}

TEST(FrameRunJson, AnotherDocumentIsABadInputNamingTheFile) {
  try {
    FrameRunFromJson(nlohmann::json{{"kind", "stitch"}}, "units/x/frame_run.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("units/x/frame_run.json: not a stitching frame run"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace aerocal::stitch
