// aerocal export: an adjustment's exposures and points in any CRS, and a GeoJSON of the
// check-point errors (triangulation/georef/crs_export.h); with --tables, every table of an adjust
// or flight result as CSV and GeoJSON for spreadsheets and GIS (tools/report/aerocal_tables.py).
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/result_file.h"
#include "tools/command_registry.h"
#include "tools/observation_tables.h"
#include "tools/python_script.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/crs_export.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace aerocal::tools {
namespace {

struct ExportArgs {
  std::string project, result, write_crs, out, tables;
};

// --tables DIR: the result's tables in the CRS of the project's `frame: {crs: ...}` (none: the
// coordinates of a projected or local frame, as the result holds them).
int WriteTables(const ExportArgs& args) {
  CheckOutputFolder(args.tables, "--tables");
  nlohmann::json result =
      ReadResult(args.result, {"adjust", "flight"}, "`aerocal adjust` or `aerocal flight`");
  // `flight --residuals-csv`: its tables are there and are the result's (checked here, so a
  // changed or missing one is a bad input, exit 2, before the script runs).
  InflateResidualTables(&result, args.result);
  std::vector<std::string> script_args = {args.result, args.tables};
  if (!args.project.empty()) {
    const triangulation::Project project = triangulation::ReadProject(args.project);
    if (!project.frame.crs.empty()) script_args.push_back(project.frame.crs);
  }
  const char* env = std::getenv("AEROCAL_TABLES_SCRIPT");
  const std::string script = env ? env : AEROCAL_TABLES_SCRIPT;
  if (!RunPythonScript(script, script_args)) {
    std::fprintf(stderr,
                 "error: the tables could not be written (%s)\n",
                 PythonCommandLine(script, script_args).c_str());
    return kExitInternal;
  }
  return kExitOk;
}

CommandRun SetupExport(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  app.add_option("--project",
                 args->project,
                 "The project adjusted (its frame: {crs: ...}); required by --write-crs, with "
                 "--tables it names the GeoJSON's CRS");
  app.add_option(
         "--result", args->result, "result.json of aerocal adjust (--tables: also of flight)")
      ->required();
  auto* write_crs =
      app.add_option("--write-crs",
                     args->write_crs,
                     "CRS to write (EPSG code, compound EPSG:A+B, WKT or PROJ string)");
  auto* out = app.add_option(
      "--out", args->out, "Output folder: exposures, points and check-point errors in --write-crs");
  auto* tables = app.add_option(
      "--tables",
      args->tables,
      "Output folder: every table of the result as CSV (exposures, points, point errors, "
      "residuals with w and r, camera parameters with sigmas and correlations) and the point "
      "errors as GeoJSON, one subfolder per adjustment (tools/report/aerocal_tables.py)");
  write_crs->needs(out);
  out->needs(write_crs);
  tables->excludes(write_crs);
  return [args]() {
    if (!args->tables.empty()) return WriteTables(*args);
    if (args->write_crs.empty())
      throw ConfigError("export: give --write-crs and --out, or --tables");
    if (args->project.empty()) throw ConfigError("--write-crs: needs --project");
    CheckOutputFolder(args->out, "--out");
    const triangulation::Project project = triangulation::ReadProject(args->project);
    const nlohmann::json result = ReadJsonFile(args->result);
    try {
      triangulation::ExportResultInCrs(project, result, args->write_crs, args->out);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(args->result + ": not an aerocal adjust result (" + e.what() + ")");
    }
    std::printf("wrote %s/exposures.csv, points.csv (%s), check_errors.geojson, crs.txt\n",
                args->out.c_str(),
                args->write_crs.c_str());
    return kExitOk;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(export_crs,
                         "export",
                         "Write an adjustment's exposures and points in any CRS (--write-crs) "
                         "and a GeoJSON of the check-point errors; --tables: every table of a "
                         "result as CSV and GeoJSON",
                         SetupExport);

}  // namespace aerocal::tools
