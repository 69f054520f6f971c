// The camera files (YAML, strict): the frame camera, a camera of any registered model, the rig
// and the line camera, each parsed from the same text and written back.
#include "calib/camera/camera_io.h"
#include "calib/camera/line_camera_io.h"
#include "calib/camera/rig_io.h"
#include "calib/core/yaml_util.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const aerocal::calib::Camera camera =
        aerocal::calib::ParseCamera(aerocal::LoadYamlText(text, "fuzz.yaml"), "fuzz.yaml");
    (void)aerocal::calib::CameraToYaml(camera);
  });
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const aerocal::calib::ModelCamera camera =
        aerocal::calib::ParseModelCamera(aerocal::LoadYamlText(text, "fuzz.yaml"), "fuzz.yaml");
    (void)aerocal::calib::ModelCameraToYaml(camera, "fuzz");
  });
  AEROCAL_FUZZ_EXPECTED_ERRORS(
      { (void)aerocal::calib::ParseRig(aerocal::LoadYamlText(text, "fuzz.yaml"), "fuzz.yaml"); });
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    (void)aerocal::calib::ParseLineCamera(aerocal::LoadYamlText(text, "fuzz.yaml"), "fuzz.yaml");
  });
  return 0;
}
