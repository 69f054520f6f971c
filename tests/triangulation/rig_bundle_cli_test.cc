// aerocal adjust on a simulated dual-lens rig flight (simulate --rig dual-lens): exit codes, the
// rig keys of the result, --write-camera (the rig file for the next flight, read back and used
// with weighted mounts), the --rig-* options, and a rig that cannot be determined (exit 3, no
// file).
#include "calib/camera/rig_io.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

namespace aerocal {
namespace {

using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

class RigAdjustCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r =
        RunAerocal("simulate --rig dual-lens --exposures 12 --out " + dir_.File("flight"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  std::string Adjust(const std::string& options, const std::string& out) {
    return "adjust --project " + dir_.File("flight") + " --out " + dir_.File(out) + " " + options;
  }
  TempDir dir_{"aerocal_rig_adjust_cli"};
};

TEST_F(RigAdjustCommand, WritesTheRigResultAndTheRigFile) {
  const auto r =
      RunAerocal(Adjust("--mkdir --write-camera " + dir_.File("next/rig.yaml"), "result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("head B mount (deg)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("is not separable"), std::string::npos);  // lever arm ~ mount at 1200 m
  const auto j = ReadJson(dir_.File("result.json"));
  ASSERT_TRUE(j.contains("rig") && j.contains("rig_exposures"));
  const auto& heads = j["rig"]["heads"];
  ASSERT_EQ(heads.size(), 2u);
  EXPECT_TRUE(heads[0]["reference"].get<bool>());
  for (const char* key :
       {"interior", "interior_sigma", "mount_deg", "lever_arm_m", "time_offset_ms"})
    EXPECT_TRUE(heads[1].contains(key)) << key;
  // Mounted blocks in the one form {mode, value, sigma}: head B's as the options say, the
  // reference head's held (the rig's datum) with null sigmas; time offsets held by default.
  EXPECT_EQ(heads[1]["mount_deg"]["mode"], "free");
  EXPECT_EQ(heads[1]["lever_arm_m"]["mode"], "free");
  EXPECT_GT(heads[1]["mount_deg"]["sigma"][1].get<double>(), 0.0);
  for (const char* key : {"mount_deg", "lever_arm_m", "time_offset_ms"}) {
    EXPECT_EQ(heads[0][key]["mode"], "fixed") << key;
    for (const auto& s : heads[0][key]["sigma"]) EXPECT_TRUE(s.is_null()) << key;
  }
  EXPECT_EQ(heads[1]["time_offset_ms"]["mode"], "fixed");
  EXPECT_TRUE(heads[1]["time_offset_ms"]["sigma"][0].is_null());
  EXPECT_TRUE(j["rig_exposures"][0]["sigma"]["dphi"].is_null()) << "held increment: no sigma";
  EXPECT_EQ(j["rig"]["options"]["mounts"], "free");
  EXPECT_EQ(j["rig_exposures"].size(), 12u);  // 12 exposures x head B
  EXPECT_TRUE(j["rig"]["determinability"]["determinable"].get<bool>());
  // The written rig file holds the estimates, their sigmas as the next flight's a-priori sigmas.
  const calib::Rig next = calib::ReadRig(dir_.File("next/rig.yaml"));
  const calib::RigHead& b = next.heads[next.HeadIndex("B")];
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(
        b.mount_rad(i) * 180.0 / M_PI, heads[1]["mount_deg"]["value"][i].get<double>(), 1e-12);
    EXPECT_NEAR(b.lever_arm_m(i), heads[1]["lever_arm_m"]["value"][i].get<double>(), 1e-12);
    ASSERT_TRUE(b.mount_sigma_rad.has_value());
    EXPECT_NEAR((*b.mount_sigma_rad)(i)*180.0 / M_PI,
                heads[1]["mount_deg"]["sigma"][i].get<double>(),
                1e-12);
  }
  // The next flight: the written rig with weighted mounts and lever arms.
  std::filesystem::copy_file(dir_.File("next/rig.yaml"),
                             dir_.File("flight/rig_nominal.yaml"),
                             std::filesystem::copy_options::overwrite_existing);
  const auto again =
      RunAerocal(Adjust("--rig-mounts weighted --rig-lever-arms weighted", "again.json"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(ReadJson(dir_.File("again.json"))["rig"]["options"]["lever_arms"], "weighted");
}

TEST_F(RigAdjustCommand, WeightedIncrementsAndTimeOffsetsWithVelocity) {
  // dT = 3 ms at 55 m/s moves head B by 0.165 m along the track. The aircraft turns between
  // strips, so R t (lever arm along x) and v dT flip together: with a free lever arm the two are
  // one unknown (said by name); with the lever arm known, the data give dT.
  const auto sim = RunAerocal(
      "simulate --rig dual-lens --exposures 12 --speed-mps 55 "
      "--head-time-offset-ms 3 --head-increment-arcsec 2 --out " +
      dir_.File("moving"));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string run = "adjust --project " + dir_.File("moving") + " --out " +
                          dir_.File("moving.json") +
                          " --rig-time-offsets weighted --rig-time-offset-sigma-ms 50"
                          " --rig-increments weighted --rig-increment-sigma-arcsec 5";
  const auto free = RunAerocal(run);
  EXPECT_NE(free.output.find("lever arm.tx is not separable from rig rig1 head B time offset.dT"),
            std::string::npos)
      << free.output;
  const auto r = RunAerocal(run + " --rig-lever-arms fixed --self-calibration c,x0,y0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(dir_.File("moving.json"));
  EXPECT_EQ(j["rig"]["options"]["time_offset_sigma_ms"].get<double>(), 50.0);
  EXPECT_NEAR(j["rig"]["options"]["increment_sigma_arcsec"].get<double>(), 5.0, 1e-12);
  const auto& b = j["rig"]["heads"][1];
  ASSERT_EQ(b["time_offset_ms"]["mode"], "weighted");
  const double dt = b["time_offset_ms"]["value"][0].get<double>(),
               sigma = b["time_offset_ms"]["sigma"][0].get<double>();
  EXPECT_GT(sigma, 0.0);
  EXPECT_LT(std::abs(dt - 3.0), 3.0 * sigma) << dt << " +- " << sigma;
  EXPECT_LT(sigma, 5.0);  // the data, not the 50 ms prior, determine it
  EXPECT_EQ(b["lever_arm_m"]["mode"], "fixed");
  EXPECT_TRUE(b["lever_arm_m"]["sigma"][0].is_null()) << "held: no sigma, never 0";
  EXPECT_GT(j["rig_exposures"][0]["sigma"]["dphi"].get<double>(), 0.0);
}

TEST_F(RigAdjustCommand, UndeterminableRigIsExitThreeWithoutRigFile) {
  const auto r = RunAerocal(
      Adjust("--rig-increments free --no-snooping --write-camera " + dir_.File("rig.yaml"),
             "result.json"));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  // The null space by name: the mount and the increments of head B.
  EXPECT_NE(r.output.find("cannot determine"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("head B mount."), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.File("rig.yaml")));
  EXPECT_FALSE(ReadJson(dir_.File("result.json"))["valid"].get<bool>());
}

TEST_F(RigAdjustCommand, BadRigOptionsAreExitTwoWithNothingWritten) {
  struct Case {
    std::string options, message;
  };
  for (const Case& c : {Case{"--rig-mounts loose", "--rig-mounts must be fixed, free or weighted"},
                        Case{"--rig-increments weighted", "--rig-increment-sigma-arcsec"},
                        Case{"--rig-time-offsets free", "exposures.csv:2"},
                        Case{"--rig-mounts weighted", "mount_sigma_deg"},
                        Case{"--compare", "not available for a rig"},
                        Case{"--joint-stitching per-flight --joint-model affine",
                             "is a rig: the joint adjustment"}}) {
    const auto r = RunAerocal(Adjust(c.options, "bad.json"));
    EXPECT_EQ(r.exit_code, 2) << c.options << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.options << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_.File("bad.json"))) << c.options;
  }
  // A frame-camera project takes no --rig-* option.
  ASSERT_EQ(RunAerocal("simulate --exposures 6 --out " + dir_.File("frame")).exit_code, 0);
  const auto r = RunAerocal("adjust --project " + dir_.File("frame") + " --out " +
                            dir_.File("bad.json") + " --rig-mounts fixed");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("need a rig camera file"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace aerocal
