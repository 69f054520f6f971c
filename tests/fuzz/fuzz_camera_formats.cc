// Other tools' camera files (calib/camera/formats): every reader of the registry on the same
// bytes, each read written back in its own format, and the detection of `--from auto`. The first
// byte picks nothing: all readers see every input, so a seed of any format exercises the others'
// refusals too. The registry includes the tool layer's OpenCV FileStorage row (tools/
// camera_formats.cc is compiled in), read as YAML, XML and JSON by the file name's ending.
#include "calib/camera/formats/camera_formats.h"
#include "tests/fuzz/fuzz_support.h"

#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const aerocal::calib::CameraReadOptions options;  // sizes from the file only
  for (const aerocal::calib::CameraFormat& format : aerocal::calib::CameraFormats()) {
    // Scratch names with the format's own ending (some readers and writers look at it).
    std::vector<std::string> endings = {format.extension};
    if (format.name == "opencv") endings = {".yml", ".xml", ".json"};
    for (const std::string& ending : endings) {
      const std::string name = "camera_" + format.name + ending;
      const std::string path = aerocal::fuzz::WriteScratch(name, text);
      AEROCAL_FUZZ_EXPECTED_ERRORS({
        const aerocal::calib::CameraFile camera = format.read(path, options);
        format.write(aerocal::fuzz::ScratchDir() + "/out_" + name, camera);
      });
    }
  }
  const std::string path = aerocal::fuzz::WriteScratch("camera_auto", text);
  AEROCAL_FUZZ_EXPECTED_ERRORS({ aerocal::calib::ReadCameraFileAs("auto", path, options); });
  return 0;
}
