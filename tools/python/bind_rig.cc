// aerocal.rig_stitch: the self-calibrating stitching of a rig block as `aerocal rig stitch` runs it
// (tools/rig_stitch_run.h: the same request and run), with the result document as the command
// writes it (the stitched images stay with the command).
#include "calib/camera/rig_io.h"
#include "calib/core/error.h"
#include "calib/core/finding.h"
#include "calib/core/result_file.h"
#include "tools/python/bindings.h"
#include "tools/rig_design_document.h"
#include "tools/rig_error_analysis_run.h"
#include "tools/rig_stitch_run.h"
#include "tools/rig_stitched_image_run.h"

#include <pybind11/stl.h>

namespace aerocal::python {
namespace {

namespace py = pybind11;

struct RigStitchResult {
  tools::RigStitchRun run;
  std::string json;    // as `aerocal rig stitch --out` writes it
  std::string images;  // the head images' folder given to rig_stitch ("" if none)
};

// One exposure's stitched level image as `rig stitch --stitched-out` makes it (tools/
// rig_stitched_image_run.h), held in memory: {"pixels", "mask"} as numpy arrays plus the figures
// of the command's `stitched_images[]` entry.
py::dict StitchedImage(const RigStitchResult& r,
                       const std::string& image,
                       const std::string& images,
                       bool balance,
                       int feather_px) {
  const std::string folder = images.empty() ? r.images : images;
  if (folder.empty())
    throw ConfigError("images: the folder of the head images (<image>_<head>.tif) is needed");
  if (!r.run.result.failures.empty())
    throw ConfigError("no stitched image: the self-calibration is not valid");
  if (!(feather_px >= 1 && feather_px <= 255))
    throw ConfigError("feather_px must be within 1..255 (got " + std::to_string(feather_px) + ")");
  tools::RequireRefinedExposure(r.run, image);  // before the head images are looked for
  stitch::StitchedImageOptions options;
  options.balance = balance;
  options.feather_px = feather_px;
  const calib::Camera& v = r.run.rig.virtual_camera.camera;
  tools::RigExposureImages heads = tools::OpenRigExposureImages(r.run.rig, folder, image);
  stitch::MemoryRaster pixels({v.width_px, v.height_px, 1, heads.bits()});
  stitch::MemoryRaster mask({v.width_px, v.height_px, 1, 8});
  stitch::StitchedImageReport report;
  {
    py::gil_scoped_release release;
    report = tools::StitchRigExposure(r.run, image, heads, options, &pixels, &mask);
  }
  nlohmann::json figures = tools::StitchedImageReportJson(report);
  figures["image"] = image;
  py::dict out = JsonToPython(figures.dump());
  out["pixels"] = RasterToNumpy(pixels);
  out["mask"] = RasterToNumpy(mask);
  return out;
}

RigStitchResult RigStitch(const std::string& camera,
                          const std::string& project,
                          const std::string& mode,
                          bool no_snooping,
                          double alpha,
                          std::optional<double> increment_sigma_arcsec,
                          std::optional<double> dt_sigma_ms,
                          std::optional<double> relief_m,
                          double standard_radius_px,
                          double max_sigma0,
                          double suspect_effect_limit,
                          double sigma_px,
                          const std::string& images,
                          bool match_ties) {
  for (const auto& [name, value] : {std::make_pair("standard_radius_px", standard_radius_px),
                                    std::make_pair("max_sigma0", max_sigma0),
                                    std::make_pair("suspect_effect_limit", suspect_effect_limit),
                                    std::make_pair("sigma_px", sigma_px)})
    if (!(std::isfinite(value) && value > 0))
      throw ConfigError(std::string(name) + ": must be a finite number > 0");
  tools::RigStitchRequest request;
  request.camera = camera;
  request.project = project;
  request.mode = mode;
  request.no_snooping = no_snooping;
  request.alpha = alpha;
  request.increment_sigma_arcsec = increment_sigma_arcsec;
  request.dt_sigma_ms = dt_sigma_ms;
  request.relief_m = relief_m;
  request.standard_radius_px = standard_radius_px;
  request.max_sigma0 = max_sigma0;
  request.suspect_effect_limit = suspect_effect_limit;
  request.default_sigma_px = sigma_px;
  request.images = images;
  request.match_ties = match_ties;
  if (match_ties && images.empty())
    throw ConfigError("match_ties needs images (the folder of the head images)");
  RigStitchResult out;
  {
    py::gil_scoped_release release;
    out.run = tools::RunRigStitch(request);
  }
  out.json = ResultText("rig_stitch", out.run.json);
  out.images = images;
  return out;
}

// `aerocal rig design`: the design document as a dict (the command's --out file's content).
py::object RigDesign(const std::string& camera, double height_m, int grid_cells) {
  const calib::Rig rig = calib::ReadRig(camera);
  const double height = tools::FlyingHeight(rig, height_m, camera);
  if (grid_cells < 10 || grid_cells > 4000)
    throw ConfigError("grid_cells must be within 10..4000 (got " + std::to_string(grid_cells) +
                      ")");
  stitch::RigDesign design;
  {
    py::gil_scoped_release release;
    design = stitch::DesignRig(rig, height, grid_cells);
  }
  return JsonToPython(
      ResultText("rig_design", tools::RigDesignDocument(rig, camera, height, design, "")));
}

// `aerocal rig error-analysis`: the result document as a dict (the command's --out content
// without the names of its CSV and PNG files).
py::object RigErrorAnalysis(const tools::RigErrorAnalysisRequest& request) {
  std::string text;
  {
    py::gil_scoped_release release;
    text =
        ResultText("rig_error_analysis", tools::RunRigErrorAnalysis(request, "", false).document);
  }
  return JsonToPython(text);
}

// rig_error_analysis(...): the keywords as the command's request.
py::object RigErrorAnalysisOf(const std::string& camera,
                              const std::string& limits,
                              const std::string& target,
                              const std::string& virtual_px,
                              int grid,
                              double height_m,
                              int samples,
                              std::uint64_t seed,
                              double relief_m) {
  tools::RigErrorAnalysisRequest request;
  request.camera = camera;
  request.limits = limits;
  request.target = target;
  request.virtual_px = virtual_px;
  request.grid = grid;
  request.height_m = height_m;
  request.samples = samples;
  request.seed = seed;
  request.relief_m = relief_m;
  return RigErrorAnalysis(request);
}

// RigStitchResult: validity, findings, sigma0, the per-exposure and snooping sections, the
// printed text, the JSON and the stitched images.
void BindRigStitchResult(py::module_& m) {
  py::class_<RigStitchResult>(
      m, "RigStitchResult", "The result of rig_stitch(): as `aerocal rig stitch` writes it")
      .def_property_readonly(
          "valid",
          [](const RigStitchResult& r) { return r.run.result.failures.empty(); },
          "No failure (the command's exit 0)")
      .def_property_readonly("failures",
                             [](const RigStitchResult& r) { return r.run.result.failures; })
      .def_property_readonly("warnings",
                             [](const RigStitchResult& r) {  // the result JSON's findings
                               return JsonToPython(FindingsToJson(r.run.result.warnings).dump());
                             })
      .def_property_readonly("sigma0", [](const RigStitchResult& r) { return r.run.result.sigma0; })
      .def_property_readonly(
          "rig_exposures",
          [](const RigStitchResult& r) {
            return JsonToPython(r.run.json.at("rig_exposures").dump());
          },
          "Per exposure and head: domega, dphi, dkappa (deg), dT_ms and their sigmas "
          "(None where held or not computable)")
      .def_property_readonly(
          "snooping",
          [](const RigStitchResult& r) { return JsonToPython(r.run.json.at("snooping").dump()); })
      .def_property_readonly(
          "printed",
          [](const RigStitchResult& r) { return r.run.printed; },
          "What the command prints")
      .def(
          "to_json",
          [](const RigStitchResult& r) { return r.json; },
          "The result file's text, identical to `aerocal rig stitch --out`")
      .def("stitched_image",
           &StitchedImage,
           py::arg("image"),
           py::arg("images") = "",
           py::arg("balance") = true,
           py::arg("feather_px") = 64,
           "The stitched level image of exposure `image` as `aerocal rig stitch --images DIR "
           "--stitched-out DIR` makes it, in memory: a dict with 'pixels' (numpy, the virtual "
           "format, the heads' depth), 'mask' (uint8, 255 valid) and the figures of the "
           "command's stitched_images[] entry (radiometry, overlap_disagreement_dn, "
           "valid_pixels, warnings). images: the folder of the head images <image>_<head>.tif "
           "(default: the one given to rig_stitch); balance False is --no-balance. The GIL is "
           "released while stitching.");
}

}  // namespace

void BindRig(py::module_& m) {
  BindRigStitchResult(m);
  m.def("rig_design",
        &RigDesign,
        py::arg("camera"),
        py::arg("height_m") = 0.0,
        py::arg("grid_cells") = 400,
        "The design figures of a multi-head rig as `aerocal rig design --camera CAMERA --out F` "
        "writes them, as a dict: GSD change ratios of each head against the closed form, the "
        "virtual format needed, covered area, effective format, overlap zones, standard tie "
        "positions (height_m 0: the rig file's virtual.height_m).");
  m.def("rig_error_analysis",
        &RigErrorAnalysisOf,
        py::arg("camera"),
        py::arg("limits"),
        py::arg("target") = "",
        py::arg("virtual") = "",
        py::arg("grid") = 0,
        py::arg("height_m") = 0.0,
        py::arg("samples") = 100000,
        py::arg("seed") = 1,
        py::arg("relief_m") = 100.0,
        "The conversion error analysis of a rig's virtual image as `aerocal rig error-analysis "
        "--camera CAMERA --limits LIMITS --out F` writes it, as a dict (without the names of the "
        "command's CSV and PNG files): target 'HEAD:COL,ROW', virtual 'COL,ROW' or an N x N grid; "
        "maximum error, linear propagation and Monte-Carlo (samples, seed). The GIL is released "
        "while it runs.");
  m.def("rig_stitch",
        &RigStitch,
        py::arg("camera"),
        py::arg("project"),
        py::arg("mode") = "line",
        py::arg("no_snooping") = false,
        py::arg("alpha") = 0.05,
        py::arg("increment_sigma_arcsec") = py::none(),
        py::arg("dt_sigma_ms") = py::none(),
        py::arg("relief_m") = py::none(),
        py::arg("standard_radius_px") = 400.0,
        py::arg("max_sigma0") = 3.0,
        py::arg("suspect_effect_limit") = 1.0,
        py::arg("sigma_px") = 0.5,
        py::arg("images") = "",
        py::arg("match_ties") = false,
        "The self-calibrating stitching of a rig block as `aerocal rig stitch --camera CAMERA "
        "--project PROJECT`: mode line | per-exposure | angles, the command's other options as "
        "keywords (`-` -> `_`; sigma_px is --sigma-px); match_ties with images (the head images' "
        "folder) matches the ties on the images. The stitched images are the command's "
        "(--stitched-out). A result that is not valid comes back with valid=False. The GIL is "
        "released while adjusting.");
}

}  // namespace aerocal::python
