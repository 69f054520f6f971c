// aerocal certificate: the calibration certificate of a `calibrate` result (or of a `flight`
// result), written by tools/certificate_writer.h.
#include "tools/certificate_writer.h"
#include "tools/command_registry.h"

#include <memory>

namespace aerocal::tools {
namespace {

CommandRun SetupCertificate(CLI::App& app) {
  auto args = std::make_shared<CertificateArgs>();
  app.add_option(
         "--result",
         args->result,
         "Result JSON of `aerocal calibrate`, or an `aerocal flight` result.json (in-flight "
         "calibration: image measurements, control coordinates and pixel pitch in the budget)")
      ->required();
  app.add_option("--lab",
                 args->lab,
                 "Lab YAML the user fills: lab, certificate (number, date), camera (make, model, "
                 "serial, lens), customer, conditions, signatures");
  app.add_option("--previous",
                 args->previous,
                 "The previous certificate.json (or calibrate result) to compare with");
  app.add_option("--tolerances",
                 args->tolerances,
                 "YAML quantity: allowed |change| (units of the quantity); without one, E_n <= 1");
  app.add_option("--out", args->out, "Output folder: certificate.json, .html, .pdf")->required();
  app.add_flag("--no-render", args->no_render, "Write certificate.json only (no HTML / PDF)");
  app.add_option("--quality",
                 args->quality,
                 "Result of `aerocal quality mtf` or `quality bars` (repeatable): the section "
                 "\"dynamic image resolution\" (MTF50 with U, limiting resolution, MTF curves)");
  return [args]() { return WriteCertificate(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(certificate,
                         "certificate",
                         "Calibration certificate (JSON, HTML, PDF) of a `calibrate` result, with "
                         "the comparison to a previous certificate",
                         SetupCertificate);

}  // namespace aerocal::tools
