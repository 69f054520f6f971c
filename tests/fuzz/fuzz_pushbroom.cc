// libFuzzer target of the line (pushbroom) camera's inputs and the calibration budget (issue 12):
// the first byte picks the reader, the rest is the file.
//   0: pos.csv (PosTrajectory::Read), then the line -> time -> pose interpolation at the first,
//      middle and last line and half a line outside them (what `pushbroom calibrate` asks);
//   1: the line observations (`pushbroom calibrate --observations`);
//   2: a line camera file (ReadLineCamera) written back and read again (the round trip of
//      `pushbroom calibrate --write-camera`);
//   3: the `calibrate --budget` YAML (ReadBudgetOptions).
#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "calib/camera/line_camera_io.h"
#include "tests/fuzz/fuzz_support.h"
#include "triangulation/calibration/uncertainty_budget.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/pos_trajectory.h"

namespace {

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
  } else {
    (void)triangulation::ReadBudgetOptions(fuzz::WriteScratch("budget.yaml", text));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  AEROCAL_FUZZ_EXPECTED_ERRORS(ReadOne(data[0] % 4, text));
  return 0;
}
