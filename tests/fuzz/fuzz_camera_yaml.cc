// The camera file (YAML, strict): parse, then the camera's own consistency.
#include "calib/camera/camera_io.h"
#include "calib/core/yaml_util.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const aerocal::calib::Camera camera =
        aerocal::calib::ParseCamera(aerocal::LoadYamlText(text, "fuzz.yaml"), "fuzz.yaml");
    (void)aerocal::calib::CameraToYaml(camera);
  });
  return 0;
}
