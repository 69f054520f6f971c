// The rig in a project (issue 13) and the project's `platform:` section: a fuzzed rig camera file
// named under `cameras:`, fuzzed exposures (with vX, vY, vZ), head observations and points, and a
// fuzzed tail of the project YAML (platform:, frame:), separated by "\n%%\n"; read as `adjust`
// reads them, then the platform check the adjustment applies.
#include "calib/camera/rig_io.h"
#include "tests/fuzz/fuzz_support.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/object_frame.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace aerocal;
  const auto parts = fuzz::Parts(data, size, 5);
  fuzz::WriteScratch("rig.yaml", parts[0]);
  fuzz::WriteScratch("exposures.csv", parts[1]);
  fuzz::WriteScratch("observations.csv", parts[2]);
  fuzz::WriteScratch("points.csv", parts[3]);
  const std::string project =
      fuzz::WriteScratch("project.yaml",
                         "cameras: {rig1: rig.yaml}\nexposures: exposures.csv\n"
                         "observations: observations.csv\npoints: points.csv\n" +
                             parts[4]);
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const triangulation::Project p = triangulation::ReadProject(project, 0.5);
    triangulation::ValidatePlatform(p.platform);
    const triangulation::ObjectFrame frame(p.frame);
    (void)triangulation::ToAdjustmentFrame(p, frame);
    for (const auto& [id, rig] : p.rigs) (void)calib::RigToYaml(rig);
  });
  return 0;
}
