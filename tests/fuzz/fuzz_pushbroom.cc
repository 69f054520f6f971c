// libFuzzer target of the line (pushbroom) camera's inputs and the laboratory calibration's files
// (issues 12, 37): the first byte picks the reader (a seed's first character '0'..'4' names kind
// 0..4), the rest is the file.
//   0: pos.csv (PosTrajectory::Read), then the line -> time -> pose interpolation at the first,
//      middle and last line and half a line outside them (what `pushbroom calibrate` asks);
//   1: the line observations (`pushbroom calibrate --observations`);
//   2: a line camera file (ReadLineCamera) written back and read again (the round trip of
//      `pushbroom calibrate --write-camera`);
//   3: the `calibrate --budget` YAML (ReadBudgetOptions);
//   4: the directions file of `calibrate --directions` (ReadDirections) against a fixed
//      6000 x 4000 px camera, which bounds its image positions.
#include "calib/camera/camera_io.h"
#include "calib/camera/line_camera_io.h"
#include "calib/core/yaml_util.h"
#include "tests/fuzz/fuzz_support.h"
#include "triangulation/calibration/direction_io.h"
#include "triangulation/calibration/uncertainty_budget.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/pos_trajectory.h"

#include <Eigen/Core>

#include <cstdint>
#include <string>

namespace {

constexpr int kKinds = 5;

// One reader on `text` (kind as in the header comment); outside the macro, whose argument a
// top-level comma would split.
void ReadOne(int kind, const std::string& text) {
  using namespace aerocal;
  if (kind == 0) {
    const auto pos = triangulation::PosTrajectory::Read(fuzz::WriteScratch("pos.csv", text));
    const double first = pos.first_line(), last = pos.last_line();
    for (const double line : {first - 0.5, first, 0.5 * (first + last), last, last + 0.5}) {
      if (!pos.CoversLine(line)) continue;
      Eigen::Vector3d center_m, opk_rad;
      pos.PoseAtLine(line, &center_m, &opk_rad);
    }
    (void)pos.MedianCenterSigma();
    (void)pos.MedianOpkSigma();
  } else if (kind == 1) {
    (void)triangulation::ReadLineObservations(fuzz::WriteScratch("observations.csv", text), 0.3);
  } else if (kind == 2) {
    const calib::LineCamera camera = calib::ReadLineCamera(fuzz::WriteScratch("line.yaml", text));
    const std::string copy = fuzz::ScratchDir() + "/line_copy.yaml";
    calib::WriteLineCamera(copy, camera);
    (void)calib::ReadLineCamera(copy);
  } else if (kind == 3) {
    (void)triangulation::ReadBudgetOptions(fuzz::WriteScratch("budget.yaml", text));
  } else {
    static const calib::Camera camera = calib::ParseCamera(
        LoadYamlText("pixel_size_mm: 0.004\nformat_px: [6000, 4000]\ninterior: {c: 24}\n",
                     "camera.yaml"),
        "camera.yaml");
    (void)triangulation::ReadDirections(fuzz::WriteScratch("directions.csv", text), camera, 0.3);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  const int kind = (data[0] - '0' + 256 * kKinds) % kKinds;  // '0' -> 0, ..., '4' -> 4
  AEROCAL_FUZZ_EXPECTED_ERRORS(ReadOne(kind, text));
  return 0;
}
