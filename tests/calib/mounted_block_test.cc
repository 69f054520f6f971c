// The mounted-block helper (calib/problem/mounted_block.h): one mode enum with its names, the
// prior-group rule, fixed / free / weighted blocks in the builder, and the one JSON form.
#include "calib/problem/mounted_block.h"

#include "calib/core/error.h"
#include "calib/problem/problem_builder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace aerocal::calib {
namespace {

TEST(BlockMode, NamesRoundTripAndAnUnknownModeNamesItsOption) {
  for (BlockMode mode : {BlockMode::kFixed, BlockMode::kFree, BlockMode::kWeighted})
    EXPECT_EQ(ParseBlockMode(BlockModeName(mode)), mode);
  EXPECT_FALSE(ParseBlockMode("Free").has_value());  // case matters
  EXPECT_FALSE(ParseBlockMode("").has_value());
  EXPECT_EQ(BlockModeOption("weighted", "--rig-mounts"), BlockMode::kWeighted);
  try {
    BlockModeOption("loose", "--lever-arm");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "--lever-arm must be fixed, free or weighted (got 'loose')");
  }
}

TEST(PriorGroup, OwnerThenPrior) {
  EXPECT_EQ(PriorGroup("platform"), "platform_prior");
  EXPECT_EQ(PriorGroup("rig"), "rig_prior");
  EXPECT_EQ(PriorGroup("line"), "line_prior");
  EXPECT_EQ(PriorGroup("rig_stitch"), "rig_stitch_prior");
}

// Fixed: held, no prior. Free: free, no prior. Weighted: free, one whitened prior
// r = (x - value) / sigma in the owner's group.
TEST(MountedBlock, FixedFreeAndWeightedEnterTheBuilderAsTheirModeSays) {
  ProblemBuilder builder;
  double fixed[3] = {1, 2, 3}, free[3] = {1, 2, 3}, weighted[3] = {1.0, 2.0, 3.0};
  const BlockId a = builder.AddBlock("mount a", fixed, 3, BlockKind::kOther, {"x", "y", "z"});
  const BlockId b = builder.AddBlock("mount b", free, 3, BlockKind::kOther, {"x", "y", "z"});
  const BlockId c = builder.AddBlock("mount c", weighted, 3, BlockKind::kOther, {"x", "y", "z"});
  const std::vector<double> value = {0.5, 2.0, 4.0}, sigma = {0.5, 1.0, 2.0};
  const BlockMode modes[] = {BlockMode::kFixed, BlockMode::kFree, BlockMode::kWeighted};
  const BlockId blocks[] = {a, b, c};
  ResidualId prior = -1;
  for (int k = 0; k < 3; ++k) {
    ApplyBlockMode(builder, blocks[k], modes[k]);
    const ResidualId id = AddBlockPrior(builder, blocks[k], modes[k], value, sigma, "rig", "prior");
    EXPECT_EQ(id >= 0, modes[k] == BlockMode::kWeighted) << k;
    if (id >= 0) prior = id;
  }
  EXPECT_TRUE(builder.IsBlockFixed(a));
  EXPECT_FALSE(builder.IsBlockFixed(b));
  EXPECT_FALSE(builder.IsBlockFixed(c));
  ASSERT_GE(prior, 0);
  EXPECT_EQ(builder.NumActiveResiduals(), 1);
  EXPECT_EQ(builder.ResidualGroup(prior), "rig_prior");
  EXPECT_EQ(builder.ResidualLabel(prior), "prior");
  const std::vector<double> r = builder.EvaluateResidual(prior);
  ASSERT_EQ(r.size(), 3u);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(std::abs(r[i]), std::abs(weighted[i] - value[i]) / sigma[i], 1e-15) << i;
}

TEST(MountedBlockJson, WritesModeValueSigmaAndReadsThemBack) {
  const Eigen::Vector3d value(0.1, -0.2, 1.3);
  const Eigen::VectorXd sigma = Eigen::Vector3d(0.01, std::nan(""), 0.03);
  const nlohmann::json j = MountedBlockToJson(BlockMode::kFree, value, sigma);
  EXPECT_EQ(j["mode"], "free");
  EXPECT_EQ(j["value"], nlohmann::json::array({0.1, -0.2, 1.3}));
  EXPECT_TRUE(j["sigma"][1].is_null());  // not finite: unknown
  const MountedBlockJson back = MountedBlockFromJson(j, "result.json: platform.lever_arm_m");
  EXPECT_EQ(back.mode, BlockMode::kFree);
  EXPECT_EQ(back.value, (std::vector<double>{0.1, -0.2, 1.3}));
  ASSERT_EQ(back.sigma.size(), 3u);
  EXPECT_EQ(back.sigma[0], 0.01);
  EXPECT_FALSE(back.sigma[1].has_value());
  // Fixed, sigma unknown: every sigma null.
  const nlohmann::json held = MountedBlockToJson(BlockMode::kFixed, value, std::nullopt);
  EXPECT_EQ(held["sigma"], nlohmann::json::array({nullptr, nullptr, nullptr}));
}

TEST(MountedBlockJson, ABrokenFormIsAnInputErrorNamingWhere) {
  const std::string where = "r.json: platform.boresight_deg";
  const auto message = [&](const nlohmann::json& j) {
    try {
      MountedBlockFromJson(j, where);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({{"value", {1}}, {"sigma", {nullptr}}}), where + ": missing key 'mode'");
  EXPECT_EQ(message({{"mode", "loose"}, {"value", {1}}, {"sigma", {nullptr}}}),
            where + ": mode must be fixed, free or weighted (got \"loose\")");
  EXPECT_EQ(message({{"mode", "free"}, {"value", {1, 2}}, {"sigma", {nullptr}}}),
            where + ": value and sigma must be arrays of equal length");
  EXPECT_EQ(message({{"mode", "free"}, {"value", {"a"}}, {"sigma", {nullptr}}}),
            where + ": value[0] must be a number");
}

}  // namespace
}  // namespace aerocal::calib
