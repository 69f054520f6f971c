// The platform data model (triangulation/block/platform.h) and the factory of the sensor kinds
// (triangulation/sensor/make_imaging_model.h), with the claims of docs/architecture.md "How to
// add a sensor kind" that a test can check: the factory has a model for every kind or names the
// command that adjusts it, every ImagingModel in triangulation/sensor/ is made by a factory row,
// and the generic adjustment (block_adjustment*.cc, adjust.cc) tests no kind.
#include "calib/camera/line_camera_io.h"
#include "calib/core/error.h"
#include "tests/support/rig_flight_project.h"
#include "tests/support/simulated_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/platform.h"
#include "triangulation/sensor/make_imaging_model.h"
#include "triangulation/simulation/flight_simulator.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

namespace aerocal::triangulation {
namespace {

// The repository's root, from the test data folder (tests/data).
std::string SourceFile(const std::string& relative) {
  return (std::filesystem::path(AEROCAL_TEST_DATA_DIR) / ".." / ".." / relative).string();
}

std::string ReadSource(const std::string& relative) {
  std::ifstream in(SourceFile(relative));
  EXPECT_TRUE(in.good()) << relative;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The example flight (2x3 CCDs) with its first raw sub-image observations added.
Project MixedFlight(const SimulatedFlight& f, int raw) {
  Project p = testing::ProjectFromFlight(f);
  p.observations.insert(
      p.observations.end(), f.subimage_observations.begin(), f.subimage_observations.begin() + raw);
  return p;
}

TEST(Platform, FrameAndSubimageSensorsWithDenseObservations) {
  const SimulatedFlight f = SimulateFlight(FlightSimulationOptions{});
  const Project project = MixedFlight(f, 40);
  const Platform platform = BuildPlatform(project);
  // One frame sensor for the camera, one per sub-image, in that order.
  ASSERT_EQ(platform.sensors.size(), 1 + f.nominal.subimages.size());
  EXPECT_EQ(platform.sensors[0].kind, SensorKind::kFrame);
  EXPECT_EQ(platform.sensors[0].name, "camera cam1");
  for (size_t s = 1; s < platform.sensors.size(); ++s) {
    EXPECT_EQ(platform.sensors[s].kind, SensorKind::kSubimage);
    EXPECT_EQ(platform.sensors[s].part, static_cast<int>(s) - 1);
  }
  // Every observation as (sensor, exposure, point) of its own ids.
  ASSERT_EQ(platform.observations.size(), project.observations.size());
  EXPECT_TRUE(std::is_sorted(platform.point_ids.begin(), platform.point_ids.end()));
  for (size_t i = 0; i < project.observations.size(); ++i) {
    const ImageObservation& o = project.observations[i];
    const PlatformObservation& x = platform.observations[i];
    const Sensor& sensor = platform.sensors[x.sensor];
    EXPECT_EQ(sensor.kind, ObservationKind(o)) << i;
    EXPECT_EQ(project.exposures[x.exposure].image, o.image) << i;
    EXPECT_EQ(platform.point_ids[x.point], o.point) << i;
    if (sensor.kind == SensorKind::kSubimage) {
      EXPECT_EQ(sensor.name, "sub-image " + o.subimage);
    }
  }
  EXPECT_TRUE(platform.Observes(SensorKind::kSubimage));
  EXPECT_FALSE(platform.Observes(SensorKind::kRigHead));
  EXPECT_EQ(platform.FindPoint("no such point"), -1);
}

TEST(Platform, RigHeadsCarryTheirFilesMountsAndLeverArms) {
  const SimulatedRigFlight f = SimulateRigFlight(RigFlightSimulationOptions{});
  const Project project = testing::RigFlightProject(f, f.nominal);
  const Platform platform = BuildPlatform(project);
  int heads = 0;
  for (const Sensor& s : platform.sensors) {
    if (s.kind != SensorKind::kRigHead) continue;
    ++heads;
    const calib::RigHead& head = f.nominal.heads[s.part];
    EXPECT_EQ(s.name, "head " + head.id);
    EXPECT_EQ(s.mount_rad, head.mount_rad);
    EXPECT_EQ(s.lever_arm_m, head.lever_arm_m);
  }
  EXPECT_EQ(heads, static_cast<int>(f.nominal.heads.size()));
  for (size_t i = 0; i < project.observations.size(); ++i)
    EXPECT_EQ(platform.sensors[platform.observations[i].sensor].name,
              "head " + project.observations[i].head);
}

// The factory: every kind has its model, configured; unconfigured, a kind either has a default
// or names the command that adjusts it.
TEST(SensorKindFactory, CoversEveryKind) {
  const calib::LineCamera line =
      calib::ReadLineCamera(AEROCAL_CONFIGS_DIR "/line_camera_three.yaml");
  std::vector<PosRecord> records(4);  // the fewest the cubic interpolation takes
  for (int k = 0; k < 4; ++k) {
    records[k].line = 100.0 * k;
    records[k].time_s = 0.1 * k;
  }
  const PosTrajectory pos = PosTrajectory::FromRecords(records, "pos.csv");
  ImagingModelOptions all;
  all.joint = SubimageCameraOptions{};
  all.rig = RigAdjustOptions{};
  all.line = ImagingModelOptions::Line{&line, &pos, LineScanOptions{}};
  std::set<std::string_view> names;
  for (SensorKind kind : kSensorKinds) {
    const auto configured = MakeImagingModel(kind, all);
    ASSERT_TRUE(configured) << SensorKindName(kind);
    EXPECT_EQ(configured->Kind(), kind);
    names.insert(SensorKindName(kind));
    const auto plain = MakeImagingModel(kind);
    if (plain) {
      EXPECT_EQ(plain->Kind(), kind);
    }
    EXPECT_EQ(plain == nullptr, !UnconfiguredReason(kind).empty()) << SensorKindName(kind);
  }
  EXPECT_EQ(names.size(), kSensorKinds.size());  // one name per kind
}

// The recipe's claim: a kind is its files plus one factory row. Every class in
// triangulation/sensor/ that implements ImagingModel is made in make_imaging_model.cc.
TEST(SensorKindFactory, EveryImagingModelInTheSensorFolderIsAFactoryRow) {
  const std::string factory = ReadSource("triangulation/sensor/make_imaging_model.cc");
  const std::regex model_class(R"(class (\w+) final : public ImagingModel)");
  int found = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(SourceFile("triangulation/sensor"))) {
    if (entry.path().extension() != ".h") continue;
    const std::string header =
        ReadSource("triangulation/sensor/" + entry.path().filename().string());
    for (std::sregex_iterator it(header.begin(), header.end(), model_class), end; it != end; ++it) {
      ++found;
      EXPECT_NE(factory.find("std::make_unique<" + (*it)[1].str() + ">"), std::string::npos)
          << (*it)[1] << " (" << entry.path().filename() << ") is not made by MakeImagingModel";
    }
  }
  EXPECT_GE(found, 5);  // frame, sub-image (refined and at the file's mappings), rig head, line
}

// The generic adjustment asks the platform, never an observation's columns or a kind.
TEST(BlockAdjustmentDriver, TestsNoSensorKind) {
  for (const char* file : {"triangulation/adjustment/block_adjustment.cc",
                           "triangulation/adjustment/block_adjustment_snooping.cc",
                           "triangulation/adjustment/block_adjustment_screening.cc",
                           "triangulation/adjustment/adjust.cc"}) {
    const std::string text = ReadSource(file);
    for (const char* kind_test : {".subimage.empty()",
                                  ".head.empty()",
                                  "kLineStripImage",
                                  "== SensorKind",
                                  "!= SensorKind",
                                  "Kind() ==",
                                  "ObservationKind(o) =="})
      EXPECT_EQ(text.find(kind_test), std::string::npos) << file << " tests a kind: " << kind_test;
  }
}

// Raw sub-image observations without the joint adjustment: the kind's default takes them to the
// virtual image with the camera file's mapping, and the result reports them as virtual-image
// observations there.
TEST(BlockAdjustmentDriver, RawSubimageObservationsAtTheCameraFilesMappings) {
  const SimulatedFlight f = SimulateFlight(FlightSimulationOptions{});
  const Project project = MixedFlight(f, 40);
  AdjustOptions options;
  options.data_snooping = false;
  options.estimate_covariance = false;
  options.auto_robust_start = false;
  BlockAdjustment adjustment(project, options);
  const AdjustmentResult r = adjustment.Run();
  ASSERT_TRUE(r.solve.converged) << r.solve.message;
  ASSERT_EQ(r.residuals.size(), project.observations.size());
  // A point in the overlap of two sub-images is measured in both: one entry per observation.
  std::multimap<std::pair<std::string, std::string>, Eigen::Vector2d> mapped;
  for (size_t i = f.observations.size(); i < project.observations.size(); ++i) {
    const ImageObservation& o = project.observations[i];
    const auto& s = f.nominal.subimages[f.nominal.SubimageIndex(o.subimage)];
    mapped.insert({{o.image, o.point}, s.VirtualFromSub(o.pixel)});
  }
  int found = 0;
  for (const ObservationResidual& v : r.residuals) {
    EXPECT_TRUE(v.subimage.empty());
    EXPECT_TRUE(v.head.empty());
    const auto [first, last] = mapped.equal_range({v.image, v.point});
    for (auto it = first; it != last; ++it) found += (v.measured_px - it->second).norm() < 1e-12;
  }
  EXPECT_EQ(found, 40);
}

// Rig-head observations are the rig bundle's: the plain adjustment names it at the first one.
TEST(BlockAdjustmentDriver, RigHeadObservationsNameTheRigBundle) {
  const SimulatedRigFlight f = SimulateRigFlight(RigFlightSimulationOptions{});
  const Project project = testing::RigFlightProject(f, f.nominal);
  try {
    BlockAdjustment adjustment(project, AdjustOptions{});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("image " + project.observations[0].image + " head " +
                        project.observations[0].head +
                        ": rig head observations are adjusted by "
                        "the rig bundle"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace aerocal::triangulation
