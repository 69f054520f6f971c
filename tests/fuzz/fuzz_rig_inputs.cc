// The other inputs of the rig commands: the first byte chooses the error-analysis limits YAML
// (`rig error-analysis --limits`) or the ESRI ASCII DEM (`rig convert --dem`); a DEM that reads is
// sampled at its corners and centre (bilinear interpolation next to no-data cells).
#include "calib/core/yaml_util.h"
#include "stitch/rig/dem_grid.h"
#include "stitch/rig/error_analysis.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace aerocal;
  if (size < 1) return 0;
  const int kind = data[0] % 2;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  // (outside the macro: a comma between braces would split its argument)
  static constexpr double kFractions[] = {0.0, 0.5, 1.0};
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    if (kind == 0) {
      (void)stitch::ParseErrorLimits(LoadYamlText(text, "limits.yaml"), "limits.yaml");
    } else {
      const stitch::DemGrid dem = stitch::ReadDemAscii(fuzz::WriteScratch("dem.asc", text));
      (void)dem.MeanHeight();
      const double w = dem.cell_m * (dem.cols - 1);
      const double h = dem.cell_m * (dem.rows - 1);
      for (const double fx : kFractions)
        for (const double fy : kFractions) (void)dem.HeightAt(dem.x0_m + fx * w, dem.y0_m + fy * h);
    }
  });
  return 0;
}
