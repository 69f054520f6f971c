// The document of `aerocal rig design` (kind rig_design): shared by the command and Python's
// `aerocal.rig_design`.
#pragma once

#include "calib/camera/rig.h"
#include "stitch/rig/rig_design.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::tools {

/// The design figures `d` of `rig` (read from `camera_file`) at `height_m` as the result
/// document; `svg` names the footprint plot written beside it ("" : none).
nlohmann::json RigDesignDocument(const calib::Rig& rig,
                                 const std::string& camera_file,
                                 double height_m,
                                 const stitch::RigDesign& d,
                                 const std::string& svg);

/// The relative flying height: `given_m` when not 0, else the rig file's virtual.height_m;
/// ConfigError naming --height-m when neither is usable (1 .. 100000 m).
double FlyingHeight(const calib::Rig& rig, double given_m, const std::string& file);

}  // namespace aerocal::tools
