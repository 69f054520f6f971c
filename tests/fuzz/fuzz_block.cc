// The block files: a project YAML naming a fixed camera and three fuzzed CSV files (exposures,
// observations, points, separated by "\n%%\n"), read as `adjust` reads them, with the frame
// conversion (GeographicLib) of a geodetic frame when the project asks for one.
#include "calib/camera/camera_io.h"
#include "tests/fuzz/fuzz_support.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/object_frame.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace aerocal;
  const auto parts = fuzz::Parts(data, size, 4);
  fuzz::WriteScratch("camera.yaml",
                     "pixel_size_mm: 0.009\nformat_px: [14000, 12000]\ninterior: {c: 170}\n"
                     "subimages:\n  - {id: I, format_px: [7100, 4134], model: affine}\n");
  fuzz::WriteScratch("exposures.csv", parts[0]);
  fuzz::WriteScratch("observations.csv", parts[1]);
  fuzz::WriteScratch("points.csv", parts[2]);
  const std::string project =
      fuzz::WriteScratch("project.yaml",
                         "cameras: {cam1: camera.yaml}\nexposures: exposures.csv\n"
                         "observations: observations.csv\npoints: points.csv\n" +
                             parts[3]);
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const triangulation::Project p = triangulation::ReadProject(project, 0.5);
    const triangulation::ObjectFrame frame(p.frame);
    (void)triangulation::ToAdjustmentFrame(p, frame);
  });
  return 0;
}
