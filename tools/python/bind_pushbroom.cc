// aerocal.pushbroom_calibrate: the line camera calibration from cloud control as `aerocal pushbroom
// calibrate` runs it (tools/pushbroom_calibrate_run.h: the same request and run), with the result
// document as the command writes it.
#include "calib/core/result_file.h"
#include "tools/pushbroom_calibrate_run.h"
#include "tools/pushbroom_control_run.h"
#include "tools/python/bindings.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

namespace aerocal::python {
namespace {

namespace py = pybind11;

struct LineCalibrationResult {
  tools::LineCalibrationRun run;
  std::string json;  // as `aerocal pushbroom calibrate --out` writes it
};

LineCalibrationResult PushbroomCalibrate(const std::string& camera,
                                         const std::string& pos,
                                         const std::string& observations,
                                         const std::string& points,
                                         const py::kwargs& kwargs) {
  tools::LineCalibrationRequest request;
  request.camera = camera;
  request.pos = pos;
  request.observations = observations;
  request.points = points;
  auto& o = request.options;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (name == "sigma_px")
      request.sigma_px = value.cast<double>();
    else if (name == "degree")
      request.degree = py::str(value).cast<std::string>();
    else if (name == "datum")
      request.datum = value.cast<std::string>();
    else if (name == "pos_prior")
      request.pos_prior = value.cast<std::string>();
    else if (name == "boresight")
      request.boresight = value.cast<std::string>();
    else if (name == "lever_arm")
      request.lever_arm = value.cast<std::string>();
    else if (name == "boresight_sigma_deg")
      request.boresight_sigma_deg = value.cast<double>();
    else if (name == "node_spacing")
      o.node_spacing_lines = value.cast<int>();
    else if (name == "max_degree")
      o.max_degree = value.cast<int>();
    else if (name == "degree_alpha")
      o.degree_test_alpha = value.cast<double>();
    else if (name == "reference")
      o.reference_subcamera = value.cast<int>();
    else if (name == "gauge_threshold")
      o.gauge_threshold = value.cast<double>();
    else if (name == "free_c")
      o.free_c = value.cast<bool>();
    else if (name == "pos_sigma_m")
      o.pos_sigma_m = value.cast<double>();
    else if (name == "pos_sigma_deg")
      o.pos_sigma_deg = value.cast<double>();
    else if (name == "lever_arm_sigma_m")
      o.lever_arm_sigma_m = value.cast<double>();
    else if (name == "time_offset")
      o.time_offset = value.cast<bool>();
    else if (name == "min_per_segment")
      o.min_observations_per_segment = value.cast<int>();
    else
      throw py::type_error(
          "pushbroom_calibrate: unknown option '" + name +
          "' (known: sigma_px, degree, datum, pos_prior, boresight, lever_arm, "
          "boresight_sigma_deg, node_spacing, max_degree, degree_alpha, reference, "
          "gauge_threshold, free_c, pos_sigma_m, pos_sigma_deg, lever_arm_sigma_m, "
          "time_offset, min_per_segment)");
  }
  if (!(std::isfinite(request.sigma_px) && request.sigma_px > 0 && request.sigma_px <= 100))
    throw ConfigError("sigma_px: must be in (0, 100]");
  LineCalibrationResult out;
  {
    py::gil_scoped_release release;
    out.run = tools::RunLineCalibration(request);
  }
  out.json = ResultText("pushbroom", out.run.json, 1);
  return out;
}

// The options of `aerocal pushbroom control` by their keyword (the option's name, `-` -> `_`).
void SetControlOption(const std::string& name,
                      const py::handle& value,
                      triangulation::CloudControlOptions* o) {
  if (name == "mean_height_m")
    o->mean_height_m = value.cast<double>();
  else if (name == "gsd_m")
    o->gsd_m = value.cast<double>();
  else if (name == "map_step")
    o->map_step_px = value.cast<int>();
  else if (name == "template_half")
    o->template_half_px = value.cast<int>();
  else if (name == "search_px")
    o->search_px = value.cast<int>();
  else if (name == "min_correlation")
    o->min_correlation = value.cast<double>();
  else if (name == "max_interest")
    o->foerstner.max_points = value.cast<int>();
  else if (name == "interest_spacing")
    o->foerstner.suppression_px = value.cast<int>();
  else if (name == "interest_weight")
    o->foerstner.weight_factor = value.cast<double>();
  else if (name == "min_match_sigma_px")
    o->min_match_sigma_px = value.cast<double>();
  else if (name == "line_sigma_px")
    o->line_sigma_px = value.cast<double>();
  else if (name == "gross_error_alpha")
    o->gross_error_alpha = value.cast<double>();
  else if (name == "max_point_sigma_m")
    o->max_point_sigma_m = value.cast<double>();
  else if (name == "line_outlier_k")
    o->line_outlier_k = value.cast<double>();
  else if (name == "line_outlier_min_px")
    o->line_outlier_min_px = value.cast<double>();
  else
    throw py::type_error("pushbroom_control: unknown option '" + name +
                         "' (known: mean_height_m, gsd_m, map_step, template_half, search_px, "
                         "min_correlation, max_interest, interest_spacing, interest_weight, "
                         "min_match_sigma_px, line_sigma_px, gross_error_alpha, "
                         "max_point_sigma_m, line_outlier_k, line_outlier_min_px)");
}

// `aerocal pushbroom control`: control.json as a dict, the line observations and the control
// points as arrays (what the command writes into --out).
py::dict PushbroomControl(const std::string& camera,
                          const std::string& pos,
                          const std::string& line_image,
                          const std::string& reference_camera,
                          const std::string& reference_images,
                          const std::string& reference_exposures,
                          const std::string& reference_result,
                          const py::kwargs& kwargs) {
  tools::PushbroomControlRequest request;
  request.camera = camera;
  request.pos = pos;
  request.line_image = line_image;
  request.reference_camera = reference_camera;
  request.reference_images = reference_images;
  request.reference_exposures = reference_exposures;
  request.reference_result = reference_result;
  for (const auto& [key, value] : kwargs) SetControlOption(py::str(key), value, &request.options);
  tools::PushbroomControlRun run;
  {
    py::gil_scoped_release release;
    run = tools::RunPushbroomControl(request);
  }
  const auto& observations = run.result.observations;
  const auto& points = run.result.points;
  const py::ssize_t n = static_cast<py::ssize_t>(observations.size());
  const py::ssize_t m = static_cast<py::ssize_t>(points.size());
  py::array_t<double> detector_line({n, py::ssize_t{2}}), sigma_px(n);
  std::vector<std::string> observed_point;
  for (py::ssize_t i = 0; i < n; ++i) {
    detector_line.mutable_at(i, 0) = observations[i].detector;
    detector_line.mutable_at(i, 1) = observations[i].line;
    sigma_px.mutable_at(i) = observations[i].sigma_px;
    observed_point.push_back(observations[i].point);
  }
  py::array_t<double> xyz({m, py::ssize_t{3}}), sigma({m, py::ssize_t{3}});
  std::vector<std::string> ids;
  for (py::ssize_t i = 0; i < m; ++i) {
    for (int k = 0; k < 3; ++k) {
      xyz.mutable_at(i, k) = points[i].xyz_m ? (*points[i].xyz_m)(k) : NAN;
      sigma.mutable_at(i, k) = points[i].sigma_m(k);
    }
    ids.push_back(points[i].id);
  }
  py::dict out;
  out["document"] = JsonToPython(ResultText("pushbroom_control", run.document));
  out["observations"] = py::dict(py::arg("point") = observed_point,
                                 py::arg("detector_line") = detector_line,
                                 py::arg("sigma_px") = sigma_px);
  out["points"] = py::dict(py::arg("id") = ids, py::arg("xyz_m") = xyz, py::arg("sigma_m") = sigma);
  return out;
}

}  // namespace

void BindPushbroom(py::module_& m) {
  py::class_<LineCalibrationResult>(
      m,
      "LineCalibrationResult",
      "The result of pushbroom_calibrate(): as `aerocal pushbroom calibrate` writes it")
      .def_property_readonly(
          "valid",
          [](const LineCalibrationResult& r) { return r.run.Ok(); },
          "Valid and converged (the command's exit 0)")
      .def_property_readonly(
          "sigma0", [](const LineCalibrationResult& r) { return r.run.result.report.sigma0; })
      .def_property_readonly("sigma0_px",
                             [](const LineCalibrationResult& r) { return r.run.result.sigma0_px; })
      .def_property_readonly(
          "document",
          [](const LineCalibrationResult& r) { return JsonToPython(r.run.json.dump()); },
          "The result document as a dict (detector table, datum, per-line corrections, warnings)")
      .def_property_readonly(
          "printed",
          [](const LineCalibrationResult& r) { return r.run.printed + r.run.errors; },
          "What the command prints (summary and warnings)")
      .def(
          "to_json",
          [](const LineCalibrationResult& r) { return r.json; },
          "The result file's text, identical to `aerocal pushbroom calibrate --out`");
  m.def(
      "pushbroom_calibrate",
      &PushbroomCalibrate,
      py::arg("camera"),
      py::arg("pos"),
      py::arg("observations"),
      py::arg("points"),
      "Line camera calibration from cloud control as `aerocal pushbroom calibrate --camera CAMERA "
      "--pos POS --observations OBS --points POINTS`; the command's other options as keywords "
      "(`-` -> `_`: sigma_px, degree, datum, pos_prior, boresight, lever_arm, boresight_sigma_deg, "
      "node_spacing, max_degree, degree_alpha, reference, gauge_threshold, free_c, pos_sigma_m, "
      "pos_sigma_deg, lever_arm_sigma_m, time_offset, min_per_segment); an unknown one is a "
      "TypeError. A result that is not valid comes back with valid=False. The GIL is released "
      "while adjusting.");
  m.def("pushbroom_control",
        &PushbroomControl,
        py::arg("camera"),
        py::arg("pos"),
        py::arg("line_image"),
        py::arg("reference_camera"),
        py::arg("reference_images"),
        py::arg("reference_exposures") = "",
        py::arg("reference_result") = "",
        "Cloud control points of a line image as `aerocal pushbroom control` makes them from "
        "oriented reference frames (reference_exposures: exposures.csv, or reference_result: the "
        "block result of `aerocal adjust`; reference_images: their folder); the command's "
        "options as keywords (`-` -> `_`: mean_height_m, gsd_m, map_step, template_half, "
        "search_px, min_correlation, max_interest, interest_spacing, interest_weight, "
        "min_match_sigma_px, line_sigma_px, gross_error_alpha, max_point_sigma_m, "
        "line_outlier_k, line_outlier_min_px). Returns a dict: document (control.json), "
        "observations {point, detector_line [N, 2], sigma_px [N]} and points {id, xyz_m [M, 3], "
        "sigma_m [M, 3]} (observations.csv and points.csv of the command). The GIL is released "
        "while matching.");
}

}  // namespace aerocal::python
