// stitch_obs.csv against a fixed two-CCD camera with reference points: read and grouped by frame
// as `stitch` does (the adjustment itself is not fuzzed: it is covered by the CLI tests).
#include "calib/camera/camera_io.h"
#include "calib/core/yaml_util.h"
#include "stitch/adjustment/frame_measurements.h"
#include "stitch/simulation/stitch_simulator.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace aerocal;
  static const calib::Camera camera = calib::ParseCamera(
      LoadYamlText(
          "pixel_size_mm: 0.009\nformat_px: [14000, 8000]\ninterior: {c: 170}\n"
          "subimages:\n  - {id: I, format_px: [7100, 8000], model: affine}\n"
          "  - {id: II, format_px: [7100, 8000], model: affine, params: [1, 0, 6900, 0, 1, 0]}\n"
          "reference_points:\n  - {id: R1, subimage: I, u: 30, v: 30, U: 30, V: 30}\n",
          "camera.yaml"),
      "camera.yaml");
  const std::string path =
      fuzz::WriteScratch("stitch_obs.csv", std::string(reinterpret_cast<const char*>(data), size));
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const auto rows = stitch::ReadStitchObservations(path, 0.1);
    (void)stitch::GroupByFrame(camera, rows, path);
  });
  return 0;
}
