// aerocal.match: tie points in the overlap strips of multi-CCD frames as `aerocal match` measures
// them (tools/match_frames.h: the same request and run), as numpy columns and, with `out`, the
// command's stitch_obs.csv.
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/matching/overlap_matcher.h"
#include "tools/match_frames.h"
#include "tools/python/bindings.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

namespace aerocal::python {
namespace {

namespace py = pybind11;

py::dict Match(const std::string& camera,
               const py::object& images,
               const std::string& frame,
               const py::object& list,
               const std::string& search,
               const py::object& detector,
               bool lsm,
               double sigma_px,
               double cell_px,
               const std::string& out) {
  if (!(sigma_px > 0 && sigma_px <= 100)) throw ConfigError("sigma_px: must be in (0, 100]");
  if (!(cell_px >= 1 && cell_px <= 1e5)) throw ConfigError("cell_px: must be in [1, 100000]");
  if (!out.empty()) CheckOutputFile(out, "out");
  tools::MatchRequest request;
  request.camera = camera;
  request.images = ImagesOptionText(images);
  request.frame = frame;
  request.list = list.is_none() ? "" : py::str(list).cast<std::string>();
  request.search = search;
  request.detector = detector.is_none() ? "" : py::str(detector).cast<std::string>();
  request.lsm = lsm ? "on" : "off";
  request.sigma_px = sigma_px;
  request.cell_px = cell_px;
  tools::MatchRun run;
  {
    py::gil_scoped_release release;
    run = tools::RunMatching(request);
    if (!out.empty()) stitch::WriteMatchedObservations(out, run.rows, false, sigma_px);
  }
  const auto n = static_cast<py::ssize_t>(run.rows.size());
  py::array_t<double> uv({n, py::ssize_t{2}}), sigma(n);
  py::list frames, points, subimages;
  for (py::ssize_t i = 0; i < n; ++i) {
    const stitch::StitchObservation& o = run.rows[i];
    uv.mutable_at(i, 0) = o.u;
    uv.mutable_at(i, 1) = o.v;
    sigma.mutable_at(i) = o.sigma_px;
    frames.append(o.frame);
    points.append(o.point);
    subimages.append(o.subimage);
  }
  py::dict d;
  d["frame"] = frames;
  d["point"] = points;
  d["subimage"] = subimages;
  d["pixel"] = uv;
  d["sigma_px"] = sigma;
  d["table"] = run.table;
  return d;
}

}  // namespace

void BindMatch(py::module_& m) {
  m.def("match",
        &Match,
        py::arg("camera"),
        py::arg("images") = py::none(),
        py::arg("frame") = "",
        py::arg("list") = py::none(),
        py::arg("search") = "predicted",
        py::arg("detector") = py::none(),
        py::arg("lsm") = true,
        py::arg("sigma_px") = 0.3,
        py::arg("cell_px") = 100.0,
        py::arg("out") = "",
        "Tie points in the overlap strips of multi-CCD frames as `aerocal match`: one frame "
        "(images {sub-image id: file} or 'I=a.tif,...', frame its id) or a flight (list: CSV "
        "frame,subimage,image); search predicted (Foerstner points found by correlation at the "
        "nominal "
        "prediction) | descriptors; detector sift | foerstner (descriptors only); lsm: "
        "least-squares refinement. Returns "
        "{frame, point, subimage: lists, pixel: (N, 2) sub-image pixels, sigma_px: (N,), table: "
        "the per-strip counts}; out: also the command's stitch_obs.csv. The GIL is released.");
}

}  // namespace aerocal::python
