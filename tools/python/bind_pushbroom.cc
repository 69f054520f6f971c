// aerocal.pushbroom_calibrate: the line camera calibration from cloud control as `aerocal pushbroom
// calibrate` runs it (tools/pushbroom_calibrate_run.h: the same request and run), with the result
// document as the command writes it.
#include "calib/core/result_file.h"
#include "tools/pushbroom_calibrate_run.h"
#include "tools/python/bindings.h"

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
}

}  // namespace aerocal::python
