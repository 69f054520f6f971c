#include "triangulation/import/colmap_ties.h"

#include "calib/core/error.h"
#include "triangulation/georef/crs.h"
#include "triangulation/import/write_project.h"

#include <filesystem>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

constexpr const char* kEcef = "EPSG:4978";

// The CRS of one file of a crs: project (points_crs / exposures_crs when given, else crs).
CrsOptions FileCrs(const FrameSpec& frame, const std::string& file_crs, const std::string& what) {
  AEROCAL_CHECK(frame.kind == FrameSpec::Kind::kCrs) << "the image import writes a crs: frame";
  return {file_crs.empty() ? frame.crs : file_crs,
          frame.vertical,
          frame.geoid_grid,
          "frame: crs (" + what + ")"};
}

std::string Stem(const std::string& name) { return std::filesystem::path(name).stem().string(); }

}  // namespace

std::vector<std::pair<std::string, Eigen::Vector3d>> EcefCentres(const Project& images) {
  const CrsConverter from(FileCrs(images.frame, images.frame.exposures_crs, "exposures"));
  const CrsConverter ecef({kEcef, "", "", "ECEF"}, from.PivotDefinition());
  std::vector<std::pair<std::string, Eigen::Vector3d>> out;
  for (const Exposure& e : images.exposures)
    out.emplace_back(e.image, ecef.FromPivot(from.ToPivot(e.center_m)));
  return out;
}

ColmapTiesReport AddColmapTies(const Project& images, const Project& model) {
  ColmapTiesReport report;
  Project& p = report.project;
  p = images;
  std::map<std::string, const Exposure*>
      by_stem;  // model image id (stem) -> exposure of the import
  for (const Exposure& e : images.exposures) by_stem[Stem(e.image)] = &e;
  std::map<std::string, std::string> image_of;  // model id -> import id
  for (const Exposure& m : model.exposures) {
    const auto it = by_stem.find(m.image);
    if (it == by_stem.end()) {
      report.notes.push_back("COLMAP image " + m.image +
                             " is not an exposure of the import (no GPS position): left out");
      continue;
    }
    const calib::Camera& ours = images.cameras.at(it->second->camera);
    const calib::Camera& theirs = model.cameras.at(m.camera);
    if (ours.width_px != theirs.width_px || ours.height_px != theirs.height_px)
      throw InputError("COLMAP model: image " + m.image + " is " + std::to_string(theirs.width_px) +
                       " x " + std::to_string(theirs.height_px) + " px, its camera " +
                       it->second->camera + " " + std::to_string(ours.width_px) + " x " +
                       std::to_string(ours.height_px) + " px");
    image_of[m.image] = it->second->image;
  }
  if (image_of.empty())
    throw InputError("COLMAP model: none of its images is an exposure of the import");
  for (const Exposure& e : images.exposures)
    if (!model.FindExposure(Stem(e.image)))
      report.notes.push_back(e.image + ": not registered by COLMAP (no tie observations)");
  // Rays per point among the kept images; a point seen by one image ties nothing.
  std::map<std::string, int> rays;
  for (const ImageObservation& o : model.observations)
    if (image_of.count(o.image)) ++rays[o.point];
  for (const ImageObservation& o : model.observations) {
    if (!image_of.count(o.image) || rays[o.point] < 2) continue;
    ImageObservation kept = o;
    kept.image = image_of[o.image];
    p.observations.push_back(kept);
  }
  const CrsConverter to(FileCrs(images.frame, images.frame.points_crs, "points"));
  const CrsConverter ecef({kEcef, "", "", "COLMAP model (model_aligner, ECEF)"},
                          to.PivotDefinition());
  int dropped = 0;
  for (const GroundPoint& g : model.points) {
    if (rays[g.id] < 2) {
      dropped += rays[g.id] == 1;
      continue;
    }
    GroundPoint tie = g;
    tie.role = PointRole::kTie;
    tie.xyz_m = to.FromPivot(ecef.ToPivot(*g.xyz_m));
    if (!tie.xyz_m->allFinite())
      throw InputError("COLMAP model: point " + g.id + " cannot be converted to " +
                       images.frame.crs);
    p.points.push_back(tie);
  }
  if (dropped > 0)
    report.notes.push_back(std::to_string(dropped) + " COLMAP points left with one ray: dropped");
  p = UsableImportedBlock(p, "COLMAP model");
  return report;
}

}  // namespace aerocal::triangulation
