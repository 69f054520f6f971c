// Readers and writers of the block files of FORMATS.md: project YAML, exposures.csv,
// observations.csv (virtual or sub-image form), points.csv. Readers throw InputError with
// FILE:LINE; writers are atomic. Cross-file consistency (an observation of an unknown image or
// point, an exposure of an unknown camera) is checked by ValidateProject with the line cited.
#pragma once

#include "triangulation/block/block.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <utility>
#include <vector>

namespace aerocal::triangulation {

std::vector<Exposure> ReadExposures(const std::string& path);
std::vector<ImageObservation> ReadObservations(const std::string& path, double default_sigma_px);
std::vector<GroundPoint> ReadPoints(const std::string& path);
/// Reads a project YAML (or a folder holding project.yaml) and every file it names, validated.
Project ReadProject(const std::string& path, double default_sigma_px = 0.5);
void ValidateProject(const Project& project);
/// The files a project was read from as (role, path) pairs: the project YAML, each camera file,
/// exposures, observations, points and the stitching measurements when named (for the result's
/// `inputs` with their checksums, calib/core/file_digest.h).
std::vector<std::pair<std::string, std::string>> ProjectFiles(const Project& project);
/// The project YAML's `platform:` map (triangulation/README.md "GNSS/IMU priors on the
/// platform"); InputError with FILE:LINE on a bad key or value.
PlatformSpec ReadPlatform(const YAML::Node& node, const std::string& path);
/// A weighted platform parameter needs its sigma > 0 (InputError naming p.source).
void ValidatePlatform(const PlatformSpec& p);

void WriteExposures(const std::string& path, const std::vector<Exposure>& exposures);
/// Writes the virtual form, or the sub-image form when any observation has a sub-image.
void WriteObservations(const std::string& path, const std::vector<ImageObservation>& observations);
void WritePoints(const std::string& path, const std::vector<GroundPoint>& points);

}  // namespace aerocal::triangulation
