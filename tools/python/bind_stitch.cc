// aerocal.stitch: the sub-image stitching of a multi-CCD camera as `aerocal stitch` runs it
// (stitch/io/stitch_from_files.h: the same option parsing and reading), with a typed result whose
// to_json() is the command's result file.
#include "calib/camera/camera_io.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/result_file.h"
#include "stitch/io/stitch_from_files.h"
#include "stitch/io/stitch_result_json.h"
#include "tools/python/bindings.h"
#include "tools/python/progress_callback.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

namespace aerocal::python {
namespace {

namespace py = pybind11;

struct StitchResult {
  stitch::BatchResult batch;
  std::string flight_model;
  bool converged = false;
  std::string json;  // as `aerocal stitch --out` writes it
};

py::dict SubimageDict(const stitch::SubimageEstimate& s) {
  py::dict d;
  d["model"] = std::string(calib::MappingModelName(s.model));
  d["base"] = s.base;
  d["params"] = Eigen::VectorXd(
      Eigen::VectorXd::Map(s.params.data(), static_cast<Eigen::Index>(s.params.size())));
  // A base sub-image is held (the datum): no sigma, None rather than 0.
  if (s.base)
    d["sigma"] = py::none();
  else
    d["sigma"] = Eigen::VectorXd(
        Eigen::VectorXd::Map(s.sigma.data(), static_cast<Eigen::Index>(s.sigma.size())));
  d["covariance"] = s.base ? py::object(py::none()) : py::cast(s.covariance);
  d["max_corner_sigma_px"] = s.max_corner_sigma_px;
  return d;
}

py::dict FrameDict(const stitch::FrameRun& run) {
  const stitch::FrameAdjustment& a = run.adjustment;
  py::dict d;
  d["frame"] = a.frame;
  d["model"] = std::string(calib::MappingModelName(a.model));
  d["model_choice"] = run.choice ? py::object(py::str(run.choice->reason)) : py::none();
  d["converged"] = a.converged;
  d["sigma0"] = a.sigma0;
  d["sigma0_px"] = a.sigma0_px;
  d["redundancy"] = a.redundancy;
  d["ties"] = a.n_ties;
  d["references"] = a.n_references;
  d["rejected"] = static_cast<int>(a.rejected.size());
  d["single_ray_points"] = a.n_single_ray_points;
  d["covariance_ok"] = a.covariance_ok;
  d["max_corner_sigma_px"] = a.max_corner_sigma_px;
  py::dict subimages;
  for (const auto& s : a.subimages) subimages[py::str(s.id)] = SubimageDict(s);
  d["subimages"] = subimages;
  d["diagnostics"] = a.diagnostics;
  return d;
}

StitchResult Stitch(const std::string& camera_path,
                    const std::string& observations,
                    const std::string& model,
                    const std::string& base,
                    double sigma_px,
                    double alpha,
                    bool no_snooping,
                    const py::object& progress_callback) {
  if (!(sigma_px > 0 && sigma_px <= 100)) throw ConfigError("sigma_px: must be in (0, 100]");
  const calib::Camera camera = calib::ReadCamera(camera_path, calib::CameraModels::kAny);
  const stitch::BatchOptions options =
      stitch::BatchOptionsFromText(camera, model, base, alpha, !no_snooping, "model", "alpha");
  const auto frames = stitch::ReadStitchFrames(camera, camera_path, observations, sigma_px);
  const auto progress =
      CallbackProgress(progress_callback, "stitch", static_cast<long>(frames.size()));
  StitchResult out;
  {
    py::gil_scoped_release release;
    out.batch = stitch::RunStitchBatch(camera, frames, options, progress.get());
  }
  const nlohmann::json doc = stitch::StitchResultToJson(out.batch, options);
  out.converged = doc.at("converged").get<bool>();
  out.flight_model = std::string(calib::MappingModelName(stitch::FlightModel(out.batch, options)));
  out.json = ResultText("stitch", doc);
  return out;
}

}  // namespace

void BindStitch(py::module_& m) {
  py::class_<StitchResult>(
      m, "StitchResult", "The result of stitch(): as `aerocal stitch` writes it")
      .def_readonly("converged", &StitchResult::converged)
      .def_readonly("flight_model",
                    &StitchResult::flight_model,
                    "The flight's model: the requested one, or the one chosen in most frames")
      .def_property_readonly(
          "frames",
          [](const StitchResult& r) {
            py::list frames;
            for (const auto& run : r.batch.frames) frames.append(FrameDict(run));
            return frames;
          },
          "Per frame: model (and model_choice's reason with model='auto'), converged, sigma0, "
          "sigma0_px, redundancy, ties, references, rejected, covariance_ok, "
          "max_corner_sigma_px, subimages {id: {model, base, params, sigma, covariance, "
          "max_corner_sigma_px}} (params in the plain form of docs/formats.md; a base "
          "sub-image's sigma and covariance are None)")
      .def_property_readonly(
          "stability",
          [](const StitchResult& r) {
            py::list out;
            for (const auto& s : r.batch.stability) {
              py::dict d;
              d["model"] = std::string(calib::MappingModelName(s.model));
              d["frames"] = s.n_frames;
              d["mean_sigma0_px"] = s.mean_sigma0_px;
              d["std_sigma0_px"] = s.std_sigma0_px;
              py::list flagged;
              for (const auto& f : s.flagged) flagged.append(py::make_tuple(f.frame, f.reasons));
              d["flagged"] = flagged;
              out.append(d);
            }
            return out;
          },
          "Per model adjusted in every frame: the flight's stability (frames out of line flagged "
          "with their reasons)")
      .def(
          "to_json",
          [](const StitchResult& r) { return r.json; },
          "The result file's text, identical to `aerocal stitch --out`");

  m.def("stitch",
        &Stitch,
        py::arg("camera"),
        py::arg("observations"),
        py::arg("model") = "auto",
        py::arg("base") = "",
        py::arg("sigma_px") = 0.1,
        py::arg("alpha") = 0.05,
        py::arg("no_snooping") = false,
        py::arg("progress") = py::none(),
        "Sub-image stitching of a multi-CCD camera as `aerocal stitch --camera CAMERA --obs "
        "OBSERVATIONS`: model translation | conformal | affine | projective | auto (F test at "
        "alpha), base: comma-separated sub-images that keep the camera file's mapping, sigma_px "
        "for rows without one; progress(done, total) per frame. The GIL is released while "
        "adjusting.");
}

}  // namespace aerocal::python
