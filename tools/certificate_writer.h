// The calibration certificate of a `calibrate` result or of an `aerocal flight` result.json (an
// in-flight calibration with a type-A budget): certificate.json, and certificate.html / .pdf
// rendered by tools/certificate/aerocal_certificate.py (tools/certificate/README.md). Used by
// `aerocal certificate` and `aerocal flight --certificate`.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::tools {

struct CertificateArgs {
  std::string result;      // calibrate result JSON or flight result.json
  std::string lab;         // lab YAML the user fills (optional)
  std::string previous;    // previous certificate.json or calibrate result (optional)
  std::string tolerances;  // YAML quantity: allowed |change| (needs previous)
  std::string out;         // output folder
  bool no_render = false;  // certificate.json only
  /// Where `result` and `out` end when the caller stages them (flight writes its outputs as one
  /// set, tools/output_set.h): the paths recorded and printed ("" = result, out themselves).
  std::string result_name, out_name;
  /// Results of `aerocal quality mtf` / `bars` / `star` (kinds quality_mtf, quality_bars,
  /// quality_star): the certificate's "dynamic image resolution" section (optional).
  std::vector<std::string> quality;
};

/// The lab YAML (sections lab, certificate, camera, customer, conditions, signatures of free-text
/// fields; an empty path gives empty fields). InputError with FILE:LINE for an unknown key or a
/// value that is not text.
nlohmann::json ReadCertificateLab(const std::string& path);

/// Writes the certificate into args.out. Returns the exit code: 0, 3 when the calibration is not
/// valid, its groups disagree or the comparison fails, 1 when rendering failed (certificate.json
/// is complete then). InputError / ConfigError for bad input (nothing written).
int WriteCertificate(const CertificateArgs& args);

}  // namespace aerocal::tools
