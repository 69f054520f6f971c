// `aerocal flight` as pieces other commands reuse: its options, their checks, and the run that
// writes result.json, the calibrated camera, the report and the certificate. `aerocal batch merge`
// runs the same flight from frames stitched apart (tools/cmd_batch.cc), so the two give the same
// files.
#pragma once

#include "triangulation/workflow/flight_workflow.h"

#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

namespace aerocal::tools {

struct FlightArgs {
  triangulation::FlightWorkflowOptions options;
  std::string out, base, joint_model = "auto", camera_format, lab, self_calibration = "auto";
  std::vector<std::string> quality;  // `aerocal quality` results for the certificate
  bool no_report = false, certificate = false;
  bool residuals_csv = false;  // residual tables as CSV beside result.json (observation_tables.h)
};

/// The options of `aerocal flight` on `app`, stored into `args`.
void AddFlightOptions(CLI::App& app, const std::shared_ptr<FlightArgs>& args);

/// Checks what can be checked before the flight runs (exit 2, nothing written) and fills
/// args->options from the textual options.
void PrepareFlight(FlightArgs* args);

/// Runs the prepared flight (args->options.stitched_frames: step 1 done apart, or null) and writes
/// its outputs; returns the exit code of `aerocal flight`.
int RunFlight(const FlightArgs& args);

}  // namespace aerocal::tools
