// aerocal.calibrate: camera calibration from a test field or a planar board as `aerocal calibrate`
// runs it (tools/calibrate_request.h: the same request, the same outcome), with the result
// document as the command writes it.
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "tools/calibrate_directions.h"
#include "tools/calibrate_request.h"
#include "tools/certificate_writer.h"
#include "tools/exit_codes.h"
#include "tools/python/bindings.h"

#include <filesystem>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <stdexcept>
#include <utility>

namespace aerocal::python {
namespace {

namespace py = pybind11;

struct CalibrationResult {
  tools::CalibrateOutcome outcome;
  std::string json;  // as `aerocal calibrate --out` writes it
};

std::string Text(const py::object& value) {
  return value.is_none() ? "" : py::str(value).cast<std::string>();
}

// {image id: array-like (N, 2) of pixels} as the request's board marks, in the dict's order.
std::vector<std::pair<std::string, std::vector<Eigen::Vector2d>>> BoardMarks(
    const py::object& corners) {
  std::vector<std::pair<std::string, std::vector<Eigen::Vector2d>>> out;
  if (corners.is_none()) return out;
  if (!py::isinstance<py::dict>(corners))
    throw ConfigError("corners: expected a dict {image id: array (N, 2) of pixels}");
  for (const auto& [id, value] : corners.cast<py::dict>()) {
    const std::string image = py::str(id).cast<std::string>();
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!a || a.ndim() != 2 || a.shape(1) != 2)
      throw ConfigError("corners['" + image + "']: expected an array of shape (N, 2) of pixels");
    std::vector<Eigen::Vector2d> marks;
    for (py::ssize_t k = 0; k < a.shape(0); ++k) marks.emplace_back(a.at(k, 0), a.at(k, 1));
    out.emplace_back(image, std::move(marks));
  }
  if (out.empty()) throw ConfigError("corners: no image given");
  return out;
}

// The result of a calibration as the command has it: its document's text, and the file `out`
// when given (either way of calibrating ends here).
CalibrationResult Finished(tools::CalibrateOutcome outcome, const std::string& out) {
  CalibrationResult result;
  result.outcome = std::move(outcome);
  result.json = ResultText("adjust", result.outcome.doc);
  if (!out.empty()) WriteResult(out, "adjust", result.outcome.doc);
  return result;
}

CalibrationResult Calibrate(const std::string& camera,
                            const py::object& directions,
                            const py::object& observations,
                            const py::object& points,
                            const py::object& images,
                            const py::object& board,
                            const py::object& corners,
                            const py::object& groups,
                            const py::object& budget,
                            const py::object& self_calibration,
                            const py::object& model,
                            double sigma_px,
                            double board_sigma_mm,
                            const std::vector<double>& radii_mm,
                            bool no_snooping,
                            bool no_closed_form,
                            double suspect_effect_limit,
                            const py::object& write_camera,
                            const std::string& camera_format,
                            const py::object& write_marks,
                            const py::object& out) {
  if (!(sigma_px > 0 && sigma_px <= 100)) throw ConfigError("sigma_px: must be in (0, 100]");
  if (!(board_sigma_mm > 0 && board_sigma_mm <= 100))
    throw ConfigError("board_sigma_mm: must be in (0, 100]");
  if (!(suspect_effect_limit > 0 && suspect_effect_limit <= 1e3))
    throw ConfigError("suspect_effect_limit: must be in (0, 1000]");
  for (const double r : radii_mm)
    if (!(r > 0 && r <= 1e4)) throw ConfigError("radii_mm: each must be in (0, 10000]");
  if (!directions.is_none()) {  // a collimator array or a goniometer sequence
    if (!observations.is_none() || !points.is_none() || !images.is_none() || !board.is_none() ||
        !corners.is_none())
      throw ConfigError(
          "directions: give either directions, or observations and points, or images and board");
    if (!groups.is_none() || !write_marks.is_none() || no_snooping || no_closed_form)
      throw ConfigError(
          "groups, write_marks, no_snooping, no_closed_form: not options of a direction "
          "calibration");
    tools::DirectionsArgs args;
    args.camera = camera;
    args.directions = Text(directions);
    args.budget = Text(budget);
    args.out = Text(out);
    args.write_camera = Text(write_camera);
    args.camera_format = camera_format;
    args.self_calibration = Text(self_calibration);
    args.model = Text(model);
    args.sigma_px = sigma_px;
    args.radii_mm = radii_mm;
    py::gil_scoped_release release;
    return Finished(tools::CalibrateFromDirections(args), args.out);
  }
  tools::CalibrateRequest request;
  request.camera = camera;
  request.observations = Text(observations);
  request.points = Text(points);
  request.images = Text(images);
  request.board = Text(board);
  request.corners = BoardMarks(corners);
  request.groups = Text(groups);
  request.budget = Text(budget);
  request.self_calibration = Text(self_calibration);
  request.model = Text(model);
  request.sigma_px = sigma_px;
  request.board_sigma_mm = board_sigma_mm;
  request.radii_mm = radii_mm;
  request.no_snooping = no_snooping;
  request.no_closed_form = no_closed_form;
  request.suspect_effect_limit = suspect_effect_limit;
  request.write_camera = Text(write_camera);
  request.camera_format = camera_format;
  request.write_marks = Text(write_marks);
  request.out = Text(out);
  py::gil_scoped_release release;
  return Finished(tools::RunCalibration(request), request.out);
}

// `aerocal certificate`: the files written into `out` as the command writes them; the exit code
// and certificate.json as a dict.
py::tuple Certificate(const std::string& result,
                      const std::string& out,
                      const std::string& lab,
                      const std::string& previous,
                      const std::string& tolerances,
                      const std::vector<std::string>& quality,
                      bool render) {
  tools::CertificateArgs args;
  args.result = result;
  args.out = out;
  args.lab = lab;
  args.previous = previous;
  args.tolerances = tolerances;
  args.quality = quality;
  args.no_render = !render;
  int code = 0;
  {
    py::gil_scoped_release release;
    code = tools::WriteCertificate(args);
  }
  if (code == tools::kExitInternal)
    throw std::runtime_error("certificate: the renderer failed (nothing written into " + out +
                             "; the message is on stderr)");
  const std::string path = (std::filesystem::path(out) / "certificate.json").string();
  return py::make_tuple(code, JsonToPython(ReadTextFile(path)));
}

}  // namespace

void BindCalibrate(py::module_& m) {
  py::class_<CalibrationResult>(
      m, "CalibrationResult", "The result of calibrate(): as `aerocal calibrate` writes it")
      .def_property_readonly(
          "valid",
          [](const CalibrationResult& r) { return r.outcome.valid; },
          "The calibration is valid and its image groups agree (exit 0 of the command)")
      .def_property_readonly(
          "sigma0",
          [](const CalibrationResult& r) { return r.outcome.doc.at("sigma0").get<double>(); })
      .def_property_readonly(
          "calibration",
          [](const CalibrationResult& r) {
            return JsonToPython(r.outcome.doc.at("calibration").dump());
          },
          "The result's `calibration` section as a dict (values with U, budget, "
          "groups, stability, method)")
      .def_property_readonly(
          "printed",
          [](const CalibrationResult& r) { return r.outcome.printed; },
          "What the command prints")
      .def(
          "to_json",
          [](const CalibrationResult& r) { return r.json; },
          "The result file's text, identical to `aerocal calibrate --out`");
  m.def("calibrate",
        &Calibrate,
        py::arg("camera"),
        py::arg("directions") = py::none(),
        py::arg("observations") = py::none(),
        py::arg("points") = py::none(),
        py::arg("images") = py::none(),
        py::arg("board") = py::none(),
        py::arg("corners") = py::none(),
        py::arg("groups") = py::none(),
        py::arg("budget") = py::none(),
        py::arg("self_calibration") = py::none(),
        py::arg("model") = py::none(),
        py::arg("sigma_px") = 0.5,
        py::arg("board_sigma_mm") = tools::kDefaultBoardSigmaMm,
        py::arg("radii_mm") = std::vector<double>{},
        py::arg("no_snooping") = false,
        py::arg("no_closed_form") = false,
        py::arg("suspect_effect_limit") = 1.0,
        py::arg("write_camera") = py::none(),
        py::arg("camera_format") = "aerocal",
        py::arg("write_marks") = py::none(),
        py::arg("out") = py::none(),
        "Camera calibration as `aerocal calibrate`: a test field (observations, points: the CSV "
        "files), a planar board (images: a glob, board: 'chessboard:9x6:25'; or corners: "
        "{image id: array (N, 2)} of the board's marks measured elsewhere, row-major as "
        "OpenCV's detectors give them, with board) or known directions "
        "(directions: a collimator array or goniometer file); groups, budget, "
        "self_calibration, model, ... as the command's options (`-` -> `_`). A result that is not "
        "valid comes back with valid=False. The GIL is released while calibrating.");
  m.def("certificate",
        &Certificate,
        py::arg("result"),
        py::arg("out"),
        py::arg("lab") = "",
        py::arg("previous") = "",
        py::arg("tolerances") = "",
        py::arg("quality") = std::vector<std::string>{},
        py::arg("render") = true,
        "The calibration certificate of a `calibrate` (or `flight`) result as `aerocal "
        "certificate --result RESULT --out OUT` writes it: certificate.json, and with render "
        "certificate.html / .pdf, into the folder `out`. Returns (code, certificate) with the "
        "command's exit code (0; 3 when the calibration is not valid, its groups disagree or the "
        "comparison fails) and certificate.json as a dict. Bad input raises ValueError, a failed "
        "renderer RuntimeError (nothing written).");
}

}  // namespace aerocal::python
