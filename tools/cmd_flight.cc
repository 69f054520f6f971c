// aerocal flight: the whole calibration workflow of one flight, with a report for people
// (triangulation/workflow/flight_workflow.h; report by tools/report/aerocal_report.py; the
// options and the run in tools/flight_command.h, shared with `aerocal batch merge`).
#include "tools/command_registry.h"
#include "tools/flight_command.h"

namespace aerocal::tools {
namespace {

CommandRun SetupFlight(CLI::App& app) {
  auto args = std::make_shared<FlightArgs>();
  AddFlightOptions(app, args);
  return [args]() {
    PrepareFlight(args.get());
    return RunFlight(*args);
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(
    flight,
    "flight",
    "Calibrate a flight: stitching, conventional / self-calibrating / joint adjustment, report",
    SetupFlight);

}  // namespace aerocal::tools
