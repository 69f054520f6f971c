#include "tools/batch_units.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/adjustment/frame_measurements.h"
#include "stitch/io/frame_run_json.h"
#include "stitch/simulation/stitch_simulator.h"

#include <nlohmann/json.hpp>

#include <filesystem>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;

// The options a frame's stitching depends on, as text (part of every unit's hash).
std::string OptionsText(const stitch::BatchOptions& o) {
  const nlohmann::json j = {
      {"model", o.model ? std::string(calib::MappingModelName(*o.model)) : "auto"},
      {"alpha", o.alpha},
      {"base", o.stitch.base_ids},
      {"data_snooping", o.stitch.data_snooping},
      {"snooping_alpha", o.stitch.snooping_alpha},
      {"robust_start", o.stitch.robust_start},
      {"robust_scale_sigma", o.stitch.robust_scale_sigma},
      {"robust_reject_sigma", o.stitch.robust_reject_sigma}};
  return j.dump();
}

// Temporary files a killed run of this unit left beside its output (WriteFileAtomically's
// `NAME.tmpPID`): never read, removed before the unit runs again.
void RemoveLeftovers(const std::string& output) {
  const fs::path folder = fs::path(output).parent_path();
  const std::string prefix = fs::path(output).filename().string() + ".tmp";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.path().filename().string().rfind(prefix, 0) == 0) fs::remove(entry.path(), ec);
}

}  // namespace

std::shared_ptr<FlightArgs> ParseFlightArguments(const std::vector<std::string>& arguments) {
  auto args = std::make_shared<FlightArgs>();
  CLI::App app("flight");
  AddFlightOptions(app, args);
  std::vector<std::string> reversed(arguments.rbegin(),
                                    arguments.rend());  // CLI11 parses from the back
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    throw ConfigError(std::string("flight arguments: ") + e.what());
  }
  PrepareFlight(args.get());
  return args;
}

void EnterPlanDirectory(const BatchManifest& manifest) {
  std::error_code ec;
  fs::current_path(manifest.directory, ec);
  if (ec)
    throw InputError(manifest.work + "/manifest.json: the folder the flight's paths start from (" +
                     manifest.directory + ") cannot be entered: " + ec.message());
}

UnitContext MakeUnitContext(const FlightArgs& flight) {
  UnitContext c;
  c.camera = calib::ReadCamera(flight.options.camera_file);
  c.options = triangulation::FlightStitchingOptions(flight.options);
  c.shared_hash =
      HashText(std::string("aerocal ") + AEROCAL_VERSION + "\n" +
               HashText(ReadTextFile(flight.options.camera_file)) + "\n" + OptionsText(c.options));
  return c;
}

std::string UnitInputHash(const UnitContext& context,
                          const BatchManifest& manifest,
                          const BatchUnit& unit) {
  std::string input;
  try {
    input = ReadTextFile(manifest.Input(unit));
  } catch (const InputError&) {
    input = "(missing)";  // a unit without its input is never done; its run says why
  }
  return HashText(context.shared_hash + "\n" + HashText(input));
}

bool RunUnit(const UnitContext& context,
             const BatchManifest& manifest,
             const BatchUnit& unit,
             const std::string& hash,
             std::string* error,
             bool* input_error) {
  const double started = Now();
  LogUnit(manifest, unit, "start (input hash " + hash + ")");
  try {
    RemoveLeftovers(manifest.Output(unit));
    // sigma_px is in every row of the input (the plan wrote the flight's default where it lacked).
    const auto rows = stitch::ReadStitchObservations(manifest.Input(unit), 0.1);
    const auto frames = stitch::GroupByFrame(context.camera, rows, manifest.Input(unit));
    if (frames.size() != 1 || frames[0].frame != unit.frame)
      throw InputError(manifest.Input(unit) + ": expected the measurements of frame " + unit.frame);
    const stitch::FrameRun run = stitch::StitchFrame(context.camera, frames[0], context.options);
    WriteFileAtomically(manifest.Output(unit), stitch::FrameRunToJson(run).dump() + "\n");
    RecordDone(manifest, unit, hash, started, Now());
    return true;
  } catch (const std::exception& e) {
    *error = e.what();
    *input_error = dynamic_cast<const InputError*>(&e) || dynamic_cast<const ConfigError*>(&e);
  }
  RecordFailure(manifest, unit, hash, started, *error);
  return false;
}

}  // namespace aerocal::tools
