// Rig camera file (YAML) reader and writer: a camera file with a `rig` section, FORMATS.md
// "Multi-head rig", plus the optional `virtual.height_m` (nominal relative flying height of the
// rectification plane, m). Each head is read by the camera file reader (camera_io.h) from the
// head's pixel_size_mm, format_px, interior, interior_sigma (and model); the rig keys beside them
// are mount_deg, lever_arm_m, mount_sigma_deg, lever_arm_sigma_m (degrees and metres in the file,
// radians and metres in memory). Missing mount / lever arm are zero; a missing `virtual` is the
// reference head's format, pixel size, c and principal point (orientation rig); a missing
// reference_head is allowed for a rig of one head only. A file without a `rig` section is an
// ordinary camera and is read as a rig of one head (RigFromCamera). Every error is
// InputError("FILE:LINE: what").
#pragma once

#include "calib/camera/rig.h"

#include <yaml-cpp/yaml.h>

#include <string>

namespace aerocal::calib {

Rig ReadRig(const std::string& path);
Rig ParseRig(const YAML::Node& root, const std::string& file);
/// YAML text of a rig (full precision; every interior term written). Read back, it gives the same
/// rig (angles to the last bit of the degree <-> radian conversion).
std::string RigToYaml(const Rig& rig);
/// Writes atomically.
void WriteRig(const std::string& path, const Rig& rig);

/// The name of a virtual orientation in files ("rig", "level") and back (nullopt when unknown).
std::string_view VirtualOrientationName(VirtualOrientation orientation);
std::optional<VirtualOrientation> ParseVirtualOrientation(std::string_view name);

}  // namespace aerocal::calib
