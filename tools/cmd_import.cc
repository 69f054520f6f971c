// aerocal import: converts blocks from other tools (COLMAP text model, DBAT / PhotoModeler marks,
// OpenDroneMap gcp_list.txt, a drone flight's images) once into the FORMATS.md block files
// (triangulation/import).
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "tools/colmap_matching.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "triangulation/adjustment/nadir_start.h"
#include "triangulation/import/colmap_import.h"
#include "triangulation/import/colmap_ties.h"
#include "triangulation/import/dbat_import.h"
#include "triangulation/import/image_import.h"
#include "triangulation/import/odm_gcp_import.h"
#include "triangulation/import/write_project.h"

#include <cstdio>
#include <sstream>

namespace aerocal::tools {
namespace {

void Report(const triangulation::Project& p, const std::string& out) {
  std::printf("imported %zu exposures, %zu observations, %zu points -> %s/project.yaml\n",
              p.exposures.size(),
              p.observations.size(),
              p.points.size(),
              out.c_str());
}

struct MatchArgs {
  std::string match = "none";  // none | colmap
  double sigma_px = 1.0;       // a-priori sigma of the tie observations, px
  ColmapMatchingOptions colmap;
};

void AddMatchOptions(CLI::App* images, const std::shared_ptr<MatchArgs>& m) {
  images
      ->add_option(
          "--match",
          m->match,
          "Tie points after the import: none (default) or colmap (COLMAP's SIFT "
          "extraction, matching and mapper, aligned to the GNSS centres; files in OUT/colmap)")
      ->check(CLI::IsMember({"none", "colmap"}));
  images->add_option("--colmap", m->colmap.program, "COLMAP executable (default: colmap on PATH)");
  images
      ->add_option(
          "--colmap-matcher",
          m->colmap.matcher,
          "exhaustive (every pair; default) or spatial (pairs near in the EXIF GPS; large flights)")
      ->check(CLI::IsMember({"exhaustive", "spatial"}));
  images
      ->add_option("--colmap-max-image-px",
                   m->colmap.max_image_px,
                   "SIFT on images downscaled to this longer side, px (default 3200)")
      ->check(FiniteRange(100, 100000));
  images
      ->add_option("--colmap-align-error-m",
                   m->colmap.align_error_m,
                   "Inlier bound of the model's alignment to the GNSS centres, m (default 10)")
      ->check(PositiveUpTo(1e6));
  images->add_option("--sigma-px", m->sigma_px, "Sigma of the tie observations, px (default 1)")
      ->check(PositiveUpTo(100));
}

// --match colmap: COLMAP's tie points added to the imported exposures (colmap_ties.h).
triangulation::Project MatchWithColmap(const triangulation::ImageImportReport& report,
                                       const std::string& images_dir,
                                       MatchArgs m,
                                       const std::string& out) {
  m.colmap.work_dir = out + "/colmap";
  const std::string text =
      RunColmapMatching(images_dir, triangulation::EcefCentres(report.project), m.colmap);
  triangulation::ColmapImportOptions c;
  c.folder = text;
  c.sigma_px = m.sigma_px;
  c.crs = "EPSG:4978";
  const triangulation::ColmapImportReport model = triangulation::ImportColmapModel(c);
  triangulation::ColmapTiesReport ties =
      triangulation::AddColmapTies(report.project, model.project);
  for (const std::string& note : ties.notes) std::printf("note: %s\n", note.c_str());
  return ties.project;
}

void SetupImportImages(CLI::App& app,
                       const std::shared_ptr<std::string>& out,
                       const std::shared_ptr<CommandRun>& run) {
  CLI::App* images = app.add_subcommand(
      "images", "A drone flight's JPEG/TIFF images: exposures and cameras from their EXIF and XMP");
  auto o = std::make_shared<triangulation::ImageImportOptions>();
  auto gnss = std::make_shared<std::vector<double>>();
  auto attitude = std::make_shared<double>(0.0);
  images->add_option("dir", o->folder, "Folder of the images (files directly in it)")->required();
  images->add_option(
      "--crs",
      o->crs,
      "CRS of the written exposures (EPSG code, compound EPSG:A+B, WKT, PROJ string; "
      "default: the images' own, EPSG:4326+5773 or EPSG:4979 by --heights)");
  images
      ->add_option("--heights",
                   o->heights,
                   "What the images' altitudes are: egm96 (EXIF: above sea level; default) or "
                   "ellipsoidal (WGS84)")
      ->check(CLI::IsMember({"egm96", "ellipsoidal"}));
  images
      ->add_option("--gnss-sigma-m",
                   *gnss,
                   "Horizontal and vertical sigma (m) of centres without RTK standard deviations "
                   "(default: none, the centre is not weighted)")
      ->expected(2)
      ->delimiter(',')
      ->check(PositiveUpTo(1e6));
  images
      ->add_option("--attitude-sigma-deg",
                   *attitude,
                   "Sigma (deg) of the attitude from the gimbal angles (default: none)")
      ->check(PositiveUpTo(360));
  images
      ->add_option("--pixel-size-mm",
                   o->pixel_size_mm,
                   "Pixel size, mm (default: EXIF FocalPlaneXResolution, else the 35 mm "
                   "equivalent focal length)")
      ->check(PositiveUpTo(1));
  images->add_option("--out", *out, "Output folder")->required();
  auto match = std::make_shared<MatchArgs>();
  AddMatchOptions(images, match);
  images->callback([=] {
    *run = [=] {
      CheckOutputFolder(*out, "--out");
      if (!gnss->empty()) o->gnss_sigma_m = Eigen::Vector2d((*gnss)[0], (*gnss)[1]);
      if (*attitude > 0) o->attitude_sigma_deg = *attitude;
      triangulation::ImageImportReport report = triangulation::ImportImages(*o);
      for (const std::string& note : report.notes) std::printf("note: %s\n", note.c_str());
      if (match->match == "colmap")
        report.project = MatchWithColmap(report, o->folder, *match, *out);
      triangulation::WriteImageImport(report, *out);
      std::printf(
          "imported %zu exposures, %zu cameras from %s -> %s/project.yaml (tags.csv: the "
          "tag of every value)\n",
          report.project.exposures.size(),
          report.project.cameras.size(),
          o->folder.c_str(),
          out->c_str());
      if (match->match == "colmap")
        std::printf("COLMAP: %zu tie points, %zu image observations in %zu exposures\n",
                    report.project.points.size(),
                    report.project.observations.size(),
                    report.project.exposures.size());
      std::printf("%zu files not used (images_not_used.csv)", report.not_used.size());
      for (size_t i = 0; i < report.not_used.size(); ++i)
        std::printf("%s%s", i == 0 ? ": " : ", ", report.not_used[i].first.c_str());
      std::printf("\n");
      return kExitOk;
    };
  });
}

// `import colmap`: a COLMAP text model.
void SetupImportColmap(CLI::App& app,
                       const std::shared_ptr<std::string>& out,
                       const std::shared_ptr<CommandRun>& run) {
  CLI::App* colmap =
      app.add_subcommand("colmap", "COLMAP text model (cameras.txt, images.txt, points3D.txt)");
  auto c = std::make_shared<triangulation::ColmapImportOptions>();
  colmap
      ->add_option("--colmap-model",
                   c->folder,
                   "Folder of the COLMAP text model (cameras.txt, images.txt, points3D.txt)")
      ->required();
  colmap->add_option("--pixel-size-mm", c->pixel_size_mm, "Pixel size, mm (COLMAP has none)")
      ->check(PositiveUpTo(1));
  colmap->add_option("--sigma-px", c->sigma_px, "Image sigma, px")->check(PositiveUpTo(100));
  colmap->add_option("--crs",
                     c->crs,
                     "CRS of a georeferenced model (EPSG:4978 after model_aligner, or a "
                     "projected CRS): the project gets frame: {crs: ...}");
  colmap->add_option("--out", *out, "Output folder")->required();
  colmap->callback([=] {
    *run = [=] {
      CheckOutputFolder(*out, "--out");
      const auto report = triangulation::ImportColmapModel(*c);
      for (const auto& note : report.notes) std::printf("%s\n", note.c_str());
      const auto project =
          triangulation::UsableImportedBlock(report.project, c->folder + "/images.txt");
      triangulation::WriteProjectFolder(project, *out);
      Report(project, *out);
      return kExitOk;
    };
  });
}

// `import dbat`: DBAT / PhotoModeler marks with a DBAT camera.
void SetupImportDbat(CLI::App& app,
                     const std::shared_ptr<std::string>& out,
                     const std::shared_ptr<CommandRun>& run) {
  CLI::App* dbat = app.add_subcommand("dbat", "DBAT / PhotoModeler marks with a DBAT camera");
  auto d = std::make_shared<triangulation::DbatImportOptions>();
  dbat->add_option("--camera-xml", d->camera_xml, "DBAT camera XML")->required();
  dbat->add_option("--marks", d->marks, "markpts.txt: image_id, point_id, x, y[, sxy]")->required();
  dbat->add_option("--images", d->images, "images.txt: id, path")->required();
  dbat->add_option("--control", d->control, "Control points: id, label, X, Y, Z[, sxyz]");
  dbat->add_option(
      "--initial-eo", d->initial_eo, "Initial EO: id, X, Y, Z, omega, phi, kappa (deg)");
  dbat->add_option(
      "--photomodeler-export", d->photomodeler_export, "PhotoModeler bundle export (stations)");
  dbat->add_option("--sigma-px", d->default_sigma_px, "Sigma where the marks have none, px")
      ->check(PositiveUpTo(100));
  dbat->add_option(
          "--control-sigma-m", d->control_sigma_m, "Control sigma where the file has none, m")
      ->check(PositiveUpTo(1000));
  dbat->add_option("--out", *out, "Output folder")->required();
  dbat->callback([=] {
    *run = [=] {
      CheckOutputFolder(*out, "--out");
      const auto project =
          triangulation::UsableImportedBlock(triangulation::ImportDbat(*d), d->marks);
      triangulation::WriteProjectFolder(project, *out);
      Report(project, *out);
      return kExitOk;
    };
  });
}

// --control of `import odm`: comma-separated target names, or a gcp_list whose targets are control.
std::set<std::string> OdmControlIds(const std::string& control,
                                    const triangulation::OdmImportOptions& o) {
  std::set<std::string> ids;
  if (control.find(',') == std::string::npos && control.find('.') != std::string::npos) {
    triangulation::OdmImportOptions subset;
    subset.gcp_list = control;
    subset.camera = o.camera;
    subset.pixel_scale = o.pixel_scale;
    subset.crs = o.crs;
    for (const auto& p : triangulation::ImportOdmGcpList(subset).points) ids.insert(p.id);
    if (ids.empty()) throw ConfigError("--control: " + control + " lists no target");
  } else {
    for (const std::string& id : SplitCommaList(control)) ids.insert(id);
  }
  return ids;
}

// `import odm`: an OpenDroneMap gcp_list.txt.
void SetupImportOdm(CLI::App& app,
                    const std::shared_ptr<std::string>& out,
                    const std::shared_ptr<CommandRun>& run) {
  CLI::App* odm =
      app.add_subcommand("odm", "OpenDroneMap gcp_list.txt (targets in near-nadir images)");
  auto o = std::make_shared<triangulation::OdmImportOptions>();
  auto camera_file = std::make_shared<std::string>();
  auto control = std::make_shared<std::string>();
  odm->add_option("--gcp-list", o->gcp_list, "gcp_list.txt")->required();
  odm->add_option("--camera", *camera_file, "Camera file (YAML) of the images")->required();
  odm->add_option("--control",
                  *control,
                  "Control targets: comma-separated names, or a gcp_list whose targets are control "
                  "(the others become check points; default: all control)");
  odm->add_option("--sigma-px", o->sigma_px, "Image sigma, px")->check(PositiveUpTo(100));
  odm->add_option("--target-sigma-m", o->target_sigma_m, "Target survey sigma, m")
      ->check(PositiveUpTo(1000));
  odm->add_option("--pixel-scale", o->pixel_scale, "Full-format px per listed px")
      ->check(PositiveUpTo(1e6));
  odm->add_option("--crs",
                  o->crs,
                  "CRS of the list's coordinates (EPSG code, compound EPSG:A+B, WKT or PROJ "
                  "string; longitude / easting first), e.g. EPSG:4326 for a WGS84 list: the "
                  "project gets frame: {crs: ...} (default: projected, used as given)");
  odm->add_option("--out", *out, "Output folder")->required();
  odm->callback([=] {
    *run = [=] {
      CheckOutputFolder(*out, "--out");
      o->camera = calib::ReadCamera(*camera_file);
      if (!control->empty()) o->control_ids = OdmControlIds(*control, *o);
      auto project = triangulation::ImportOdmGcpList(*o);
      if (project.observations.empty())
        throw InputError(o->gcp_list + ": no image sees two or more targets: nothing to import");
      try {
        project = triangulation::WithNadirStart(project, "cam1");
      } catch (const InputError& e) {
        throw InputError(o->gcp_list + ": " + e.what());
      }
      project = triangulation::UsableImportedBlock(project, o->gcp_list);
      triangulation::WriteProjectFolder(project, *out);
      Report(project, *out);
      std::printf(
          "exposures.csv holds starting values from the targets (near-nadir similarity); "
          "adjust with --robust-start when the list may hold gross errors\n");
      return kExitOk;
    };
  });
}

CommandRun SetupImport(CLI::App& app) {
  app.require_subcommand(1);
  auto out = std::make_shared<std::string>();
  auto run = std::make_shared<CommandRun>();
  SetupImportColmap(app, out, run);
  SetupImportDbat(app, out, run);
  SetupImportOdm(app, out, run);
  SetupImportImages(app, out, run);
  return [run]() { return (*run)(); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(
    import,
    "import",
    "Convert a COLMAP model, DBAT/PhotoModeler marks, an ODM gcp_list.txt or a "
    "drone flight's images into the block files",
    SetupImport);

}  // namespace aerocal::tools
