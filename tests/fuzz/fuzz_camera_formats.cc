// Other tools' camera files (calib/camera/formats): every reader on the same bytes, each read
// written back in its own format. The first byte picks nothing: all readers see every input, so
// a seed of any format exercises the others' refusals too.
#include "calib/camera/formats/camera_formats.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using aerocal::calib::CameraFile;
using aerocal::calib::CameraReadOptions;
using Reader = CameraFile (*)(const std::string&, const CameraReadOptions&);
using Writer = void (*)(const std::string&, const CameraFile&);

struct Format {
  const char* file;  // scratch name (some readers look at the extension)
  Reader read;
  Writer write;
};

const Format kFormats[] = {
    {"cameras.txt", aerocal::calib::ReadColmapCameras, aerocal::calib::WriteColmapCameras},
    {"calib.xml", aerocal::calib::ReadMetashapeCalibration,
     aerocal::calib::WriteMetashapeCalibration},
    {"camera.cam", aerocal::calib::ReadPix4dCam, aerocal::calib::WritePix4dCam},
    {"cameras.json", aerocal::calib::ReadOpenSfmCameras, aerocal::calib::WriteOpenSfmCameras},
    {"dewarp.txt", aerocal::calib::ReadDjiDewarpData, aerocal::calib::WriteDjiDewarpData},
    {"camera.xml", aerocal::calib::ReadDbatCameraXml, aerocal::calib::WriteDbatCameraXml},
    {"camchain.yaml", aerocal::calib::ReadKalibrCamchain, aerocal::calib::WriteKalibrCamchain},
    {"pmexport.txt", aerocal::calib::ReadPhotoModelerCamera, aerocal::calib::WritePhotoModelerCamera},
    {"australis.txt", aerocal::calib::ReadAustralisCamera, aerocal::calib::WriteAustralisCamera},
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const CameraReadOptions options;  // sizes from the file, as without --width/--height/--pixel-mm
  for (const Format& format : kFormats) {
    const std::string path = aerocal::fuzz::WriteScratch(format.file, text);
    AEROCAL_FUZZ_EXPECTED_ERRORS({
      const CameraFile camera = format.read(path, options);
      format.write(aerocal::fuzz::ScratchDir() + "/out_" + format.file, camera);
    });
  }
  return 0;
}
