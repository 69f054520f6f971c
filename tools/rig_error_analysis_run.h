// `aerocal rig error-analysis` without its files: the request (the command's options), the
// checks, the target's choice and the analysis with its result document. Shared by the command
// (which writes the CSV files and plots beside --out) and Python's `aerocal.rig_error_analysis`.
#pragma once

#include "calib/camera/rig.h"
#include "stitch/rig/error_analysis.h"
#include "stitch/rig/error_analysis_json.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <string>

namespace aerocal::tools {

struct RigErrorAnalysisRequest {
  std::string camera, limits;  // rig file, limits file
  std::string target;          // HEAD:COL,ROW, or
  std::string virtual_px;      // COL,ROW in the virtual image, or
  int grid = 0;                // N: an N x N grid of targets (0: one target)
  double height_m = 0.0;       // 0: the rig file's virtual.height_m
  int samples = 100000;        // Monte-Carlo samples per target (0: linear only)
  std::uint64_t seed = 1;
  int bins = 60;  // histogram bins of the command's CSV
  double relief_m = 100.0;
};

struct RigErrorAnalysisRun {
  calib::Rig rig;
  double height_m = 0.0;
  stitch::TargetAnalysis target;               // the target, or the grid's worst point
  std::unique_ptr<stitch::GridAnalysis> grid;  // with --grid
  stitch::ErrorAnalysisFiles files;            // the names beside `stem` (none without a stem)
  nlohmann::json document;                     // kind rig_error_analysis (without the stamp)
};

/// Reads the rig and limits files, checks the request (ConfigError naming the option, InputError
/// naming the file), chooses the target and runs the analysis. `file_stem` names the CSV files
/// (STEM_histogram.csv, STEM_bound_map.csv) and, with `plots`, their PNGs in the document; ""
/// names none.
RigErrorAnalysisRun RunRigErrorAnalysis(const RigErrorAnalysisRequest& request,
                                        const std::string& file_stem,
                                        bool plots);

}  // namespace aerocal::tools
