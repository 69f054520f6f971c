// Image metadata (calib/metadata/): the JPEG marker walk, the TIFF-IFD reader of EXIF and TIFF
// files, the XMP packet parser, and the per-image values `import images` takes from them, on the
// same bytes. Seeds: the metadata-only DJI JPEGs of tests/data/images and a TIFF.
#include "calib/metadata/image_metadata.h"
#include "tests/fuzz/fuzz_support.h"
#include "triangulation/import/image_record.h"

namespace {

void ReadAsImage(const std::string& bytes) {
  const aerocal::calib::ImageMetadata meta =
      aerocal::calib::ImageMetadataOfBytes(bytes, "image.jpg");
  aerocal::triangulation::internal::ReadImageRecord(meta, "image.jpg", "image.jpg");
}

void ReadAsCameraFile(const std::string& bytes) {
  int width = 0;
  int height = 0;
  aerocal::calib::XmpOfCameraFile(bytes, "camera.xmp", &width, &height);
}

void ReadAsPacket(const std::string& bytes) {
  const aerocal::SourceRef where{"packet.xmp", 1};
  aerocal::calib::XmpPacket::Parse(bytes, where);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  AEROCAL_FUZZ_EXPECTED_ERRORS({ ReadAsImage(bytes); });
  AEROCAL_FUZZ_EXPECTED_ERRORS({ ReadAsCameraFile(bytes); });
  AEROCAL_FUZZ_EXPECTED_ERRORS({ ReadAsPacket(bytes); });
  return 0;
}
