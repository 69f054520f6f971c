// aerocal export: an adjustment's exposures and points in any CRS, and a GeoJSON of the
// check-point errors (triangulation/georef/crs_export.h).
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "tools/command_registry.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/crs_export.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

namespace aerocal::tools {
namespace {

struct ExportArgs {
  std::string project, result, write_crs, out;
};

CommandRun SetupExport(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  app.add_option("--project", args->project, "The project adjusted (its frame: {crs: ...})")
      ->required();
  app.add_option("--result", args->result, "result.json of aerocal adjust")->required();
  app.add_option("--write-crs", args->write_crs,
                 "CRS to write (EPSG code, compound EPSG:A+B, WKT or PROJ string)")
      ->required();
  app.add_option("--out", args->out, "Output folder: exposures, points and check-point errors in --write-crs")->required();
  return [args]() {
    CheckOutputFolder(args->out, "--out");
    const triangulation::Project project = triangulation::ReadProject(args->project);
    const nlohmann::json result = ReadJsonFile(args->result);
    try {
      triangulation::ExportResultInCrs(project, result, args->write_crs, args->out);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(args->result + ": not an aerocal adjust result (" + e.what() + ")");
    }
    std::printf("wrote %s/exposures.csv, points.csv (%s), check_errors.geojson, crs.txt\n",
                args->out.c_str(), args->write_crs.c_str());
    return kExitOk;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(export_crs,
                         "export",
                         "Write an adjustment's exposures and points in any CRS (--write-crs) "
                         "and a GeoJSON of the check-point errors",
                         SetupExport);

}  // namespace aerocal::tools
