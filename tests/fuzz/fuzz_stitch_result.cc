// A stitch result JSON applied to a camera (what `resample --mapping` reads).
#include "calib/camera/camera_io.h"
#include "calib/core/yaml_util.h"
#include "stitch/io/stitch_result_json.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace aerocal;
  static const calib::Camera camera = calib::ParseCamera(
      LoadYamlText(
          "pixel_size_mm: 0.009\nformat_px: [14000, 8000]\ninterior: {c: 170}\n"
          "subimages:\n  - {id: I, format_px: [7100, 8000], model: affine}\n"
          "  - {id: II, format_px: [7100, 8000], model: affine, params: [1, 0, 6900, 0, 1, 0]}\n",
          "camera.yaml"),
      "camera.yaml");
  const std::string path =
      fuzz::WriteScratch("result.json", std::string(reinterpret_cast<const char*>(data), size));
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    (void)stitch::ApplyStitchResult(camera, path, "");
    (void)stitch::ApplyStitchResult(camera, path, "0001");
  });
  return 0;
}
