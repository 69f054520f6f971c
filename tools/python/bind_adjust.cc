// aerocal.Block and aerocal.adjust: the block files (triangulation/block/block_io.h) or arrays, the
// adjustment exactly as `aerocal adjust` runs it (tools/cmd_adjust.cc: the object frame, the free
// set, `--self-calibration auto`; a rig block's rig bundle through the command's own run,
// tools/rig_adjust_run.h), the typed result with numpy arrays and to_json() identical to the
// command's result file.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/finding.h"
#include "calib/core/result_file.h"
#include "tools/project_facts.h"
#include "tools/python/bindings.h"
#include "tools/python/progress_callback.h"
#include "tools/rig_adjust_run.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/kept_adjustment.h"
#include "triangulation/adjustment/self_calibration_choice.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/object_frame.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <set>
#include <string>

namespace aerocal::python {
namespace {

namespace py = pybind11;
using triangulation::AdjustmentResult;
using triangulation::Project;

struct Block {
  Project project;
  std::string path;  // as given to Block.read ("" for a block built from arrays)
};

// The solved problem behind a frame-camera result (triangulation/adjustment/kept_adjustment.h),
// for covariance() of exposures and points; its builder is not thread-safe, hence the mutex.
struct Kept {
  triangulation::KeptAdjustment adjustment;
  std::mutex mutex;
};

struct Result {
  AdjustmentResult result;     // a rig block's: the block part of the rig bundle's result
  std::string json;            // the result file's text, as `aerocal adjust --out` writes it
  nlohmann::json rig;          // a rig block's `rig` section of that file; null for frame cameras
  std::shared_ptr<Kept> kept;  // null for a rig block (the rig bundle's run keeps nothing)
};

constexpr double kDegToRad = M_PI / 180.0;

// One column of a table given as a dict of sequences; `n` rows.
std::vector<double> NumberColumn(const py::dict& table,
                                 const char* name,
                                 size_t n,
                                 bool required,
                                 const char* what,
                                 bool nan_absent = false) {
  if (!table.contains(name)) {
    if (required) throw ConfigError(std::string(what) + ": column '" + name + "' missing");
    return {};
  }
  const auto values = table[name].cast<std::vector<double>>();
  if (values.size() != n)
    throw ConfigError(std::string(what) + ": column '" + name + "' has " +
                      std::to_string(values.size()) + " rows, expected " + std::to_string(n));
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(values[i]) && !(nan_absent && std::isnan(values[i])))
      throw ConfigError(std::string(what) + "[" + std::to_string(i) + "]." + name +
                        ": not a finite number");
  return values;
}

std::vector<std::string> TextColumn(const py::dict& table,
                                    const char* name,
                                    const char* what,
                                    std::optional<size_t> n = std::nullopt) {
  if (!table.contains(name))
    throw ConfigError(std::string(what) + ": column '" + name + "' missing");
  auto values = table[name].cast<std::vector<std::string>>();
  if (n && values.size() != *n)
    throw ConfigError(std::string(what) + ": column '" + name + "' has " +
                      std::to_string(values.size()) + " rows, expected " + std::to_string(*n));
  for (size_t i = 0; i < values.size(); ++i)
    if (values[i].empty())
      throw ConfigError(std::string(what) + "[" + std::to_string(i) + "]." + name + ": empty");
  return values;
}

Block BlockFromArrays(const std::map<std::string, calib::CameraFile>& cameras,
                      const py::dict& exposures,
                      const py::dict& points,
                      const py::dict& observations,
                      const std::string& frame) {
  Block b;
  b.project.path = "arrays";
  b.project.frame.description = frame;
  for (const auto& [id, file] : cameras) {
    calib::Camera camera = calib::Camera::OfModel(file.camera.model).WithModelCamera(file.camera);
    camera.name = file.name;
    b.project.cameras[id] = camera;
  }
  const auto images = TextColumn(exposures, "image", "exposures");
  const size_t ne = images.size();
  const auto camera_of = TextColumn(exposures, "camera", "exposures", ne);
  const char* eo[] = {"X", "Y", "Z", "omega", "phi", "kappa"};
  std::vector<std::vector<double>> e(6);
  for (int k = 0; k < 6; ++k) e[k] = NumberColumn(exposures, eo[k], ne, true, "exposures");
  for (size_t i = 0; i < ne; ++i) {
    triangulation::Exposure x;
    x.image = images[i];
    x.camera = camera_of[i];
    x.center_m = {e[0][i], e[1][i], e[2][i]};
    x.opk_rad = Eigen::Vector3d(e[3][i], e[4][i], e[5][i]) * kDegToRad;
    x.line = static_cast<int>(i) + 1;
    b.project.exposures.push_back(x);
  }
  const auto ids = TextColumn(points, "point", "points");
  const size_t np = ids.size();
  const auto roles = TextColumn(points, "role", "points", np);
  const char* xyz[] = {"X", "Y", "Z", "sX", "sY", "sZ"};
  std::vector<std::vector<double>> p(6);
  // NaN: absent (a tie point without an approximation, a tie point's sigmas), as an empty field.
  for (int k = 0; k < 6; ++k) p[k] = NumberColumn(points, xyz[k], np, k < 3, "points", true);
  for (size_t i = 0; i < np; ++i) {
    triangulation::GroundPoint g;
    g.id = ids[i];
    g.line = static_cast<int>(i) + 1;
    const Eigen::Vector3d xyz(p[0][i], p[1][i], p[2][i]);
    if (xyz.allFinite())
      g.xyz_m = xyz;
    else if (!xyz.array().isNaN().all())
      throw ConfigError("points[" + std::to_string(i) + "]: give all of X, Y, Z or none (NaN)");
    if (roles[i] == "control")
      g.role = triangulation::PointRole::kControl;
    else if (roles[i] == "check")
      g.role = triangulation::PointRole::kCheck;
    else if (roles[i] == "tie")
      g.role = triangulation::PointRole::kTie;
    else
      throw ConfigError("points[" + std::to_string(i) + "].role: control, check or tie");
    if (g.role == triangulation::PointRole::kControl && !g.xyz_m)
      throw ConfigError("points[" + std::to_string(i) + "]: a control point needs X, Y, Z");
    if (g.role != triangulation::PointRole::kTie && g.xyz_m) {
      if (p[3].empty() || !(p[3][i] > 0 && p[4][i] > 0 && p[5][i] > 0))
        throw ConfigError("points[" + std::to_string(i) +
                          "]: a surveyed point needs sX, sY, sZ > 0");
      g.sigma_m = {p[3][i], p[4][i], p[5][i]};
    }
    b.project.points.push_back(g);
  }
  const auto obs_images = TextColumn(observations, "image", "observations");
  const size_t no = obs_images.size();
  const auto obs_points = TextColumn(observations, "point", "observations", no);
  const auto col = NumberColumn(observations, "col", no, true, "observations");
  const auto row = NumberColumn(observations, "row", no, true, "observations");
  const auto sigma = NumberColumn(observations, "sigma_px", no, true, "observations");
  for (size_t i = 0; i < no; ++i) {
    if (!(sigma[i] > 0)) throw ConfigError("observations[" + std::to_string(i) + "].sigma_px: > 0");
    triangulation::ImageObservation o;
    o.image = obs_images[i];
    o.point = obs_points[i];
    o.pixel = {col[i], row[i]};
    o.sigma_px = sigma[i];
    o.line = static_cast<int>(i) + 1;
    b.project.observations.push_back(o);
  }
  triangulation::ValidateProject(b.project);
  return b;
}

py::dict ExposureTable(const Project& p) {
  std::vector<std::string> image, camera;
  Eigen::MatrixX3d center(p.exposures.size(), 3), opk(p.exposures.size(), 3);
  for (size_t i = 0; i < p.exposures.size(); ++i) {
    image.push_back(p.exposures[i].image);
    camera.push_back(p.exposures[i].camera);
    center.row(i) = p.exposures[i].center_m;
    opk.row(i) = p.exposures[i].opk_rad / kDegToRad;
  }
  py::dict d;
  d["image"] = image;
  d["camera"] = camera;
  d["center_m"] = center;
  d["opk_deg"] = opk;
  return d;
}

py::dict ObservationTable(const Project& p) {
  std::vector<std::string> image, point;
  Eigen::MatrixX2d pixel(p.observations.size(), 2);
  Eigen::VectorXd sigma(p.observations.size());
  for (size_t i = 0; i < p.observations.size(); ++i) {
    image.push_back(p.observations[i].image);
    point.push_back(p.observations[i].point);
    pixel.row(i) = p.observations[i].pixel;
    sigma(i) = p.observations[i].sigma_px;
  }
  py::dict d;
  d["image"] = image;
  d["point"] = point;
  d["pixel"] = pixel;
  d["sigma_px"] = sigma;
  return d;
}

py::dict PointTable(const Project& p) {
  std::vector<std::string> id, role;
  Eigen::MatrixX3d xyz(p.points.size(), 3);
  for (size_t i = 0; i < p.points.size(); ++i) {
    id.push_back(p.points[i].id);
    role.push_back(triangulation::PointRoleName(p.points[i].role));
    xyz.row(i) = p.points[i].xyz_m.value_or(Eigen::Vector3d::Constant(std::nan("")));
  }
  py::dict d;
  d["point"] = id;
  d["role"] = role;
  d["xyz_m"] = xyz;
  return d;
}

// The keyword options of adjust(): the command's options, `-` -> `_` (tools/cmd_adjust.cc).
triangulation::AdjustOptions OptionsFromKeywords(const py::kwargs& kw) {
  triangulation::AdjustOptions o;
  static const std::set<std::string> known = {"no_snooping",
                                              "robust_start",
                                              "no_robust_start",
                                              "max_rejections",
                                              "max_sigma0",
                                              "min_redundancy",
                                              "critical_value",
                                              "no_eo_priors",
                                              "no_interior_sigma",
                                              "max_iterations",
                                              "correlation_threshold",
                                              "suspect_effect_limit",
                                              "rig_mounts",
                                              "rig_lever_arms",
                                              "rig_increments",
                                              "rig_increment_sigma_arcsec",
                                              "rig_time_offsets",
                                              "rig_time_offset_sigma_ms"};
  for (const auto& item : kw) {
    const std::string key = item.first.cast<std::string>();
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw py::type_error("adjust() got an unknown option '" + key + "' (known: " + list + ")");
    }
  }
  auto flag = [&](const char* k) { return kw.contains(k) && kw[k].cast<bool>(); };
  auto number = [&](const char* k, double* v) {
    if (kw.contains(k)) *v = kw[k].cast<double>();
  };
  o.data_snooping = !flag("no_snooping");
  o.robust_start = flag("robust_start");
  o.auto_robust_start = !flag("no_robust_start");
  if (o.robust_start && !o.auto_robust_start)
    throw ConfigError("robust_start and no_robust_start exclude each other");
  o.use_eo_priors = !flag("no_eo_priors");
  o.use_interior_sigma = !flag("no_interior_sigma");
  if (kw.contains("max_rejections")) o.max_rejections = kw["max_rejections"].cast<int>();
  if (kw.contains("max_iterations")) o.solver.max_iterations = kw["max_iterations"].cast<int>();
  number("max_sigma0", &o.max_sigma0);
  number("min_redundancy", &o.min_redundancy);
  number("critical_value", &o.snooping_critical_value);
  number("correlation_threshold", &o.correlation_threshold);
  number("suspect_effect_limit", &o.suspect_effect_limit);
  return o;
}

// The --rig-* keywords (rig_mounts, ...); a frame-camera block refuses them, as the command.
tools::RigAdjustRequest RigRequestFromKeywords(const py::kwargs& kw, bool rig_block) {
  tools::RigAdjustRequest r;
  bool given = false;
  auto text = [&](const char* k, std::string* v) {
    if (kw.contains(k)) *v = kw[k].cast<std::string>(), given = true;
  };
  auto number = [&](const char* k, double* v) {
    if (kw.contains(k)) *v = kw[k].cast<double>(), given = true;
  };
  text("rig_mounts", &r.mounts);
  text("rig_lever_arms", &r.lever_arms);
  text("rig_increments", &r.increments);
  text("rig_time_offsets", &r.time_offsets);
  number("rig_increment_sigma_arcsec", &r.increment_sigma_arcsec);
  number("rig_time_offset_sigma_ms", &r.time_offset_sigma_ms);
  if (given && !rig_block)
    throw ConfigError(
        "rig_*: the rig options need a rig camera file (a camera file with a rig "
        "section)");
  return r;
}

// A rig block: the command's rig bundle (tools/rig_adjust_run.h), the same refusals.
Result AdjustRigBlock(const Block& block,
                      bool auto_free,
                      const triangulation::AdjustOptions& options,
                      const py::kwargs& kw) {
  tools::CheckRigProject(block.project,
                         block.path.empty() ? block.project.path : block.path,
                         false,
                         auto_free,
                         options.robust_start);
  const tools::RigAdjustRequest request = RigRequestFromKeywords(kw, true);
  tools::RigAdjustRun run;
  {
    py::gil_scoped_release release;
    run = tools::RunRigAdjust(request, options, block.project, block.path, !block.path.empty());
  }
  Result out;
  out.result = run.result.adjustment;
  out.json = ResultText("adjust", run.json);
  out.rig = run.json.at("rig");
  return out;
}

Result Adjust(const Block& block,
              const std::string& self_calibration,
              const py::object& progress_callback,
              const py::kwargs& kw) {
  const bool auto_free = self_calibration == "auto";
  triangulation::AdjustOptions options = OptionsFromKeywords(kw);
  const calib::CameraModelId model = block.project.cameras.begin()->second.model;
  for (const auto& [id, camera] : block.project.cameras)
    if (camera.model != model && self_calibration != "none")
      throw ConfigError("self_calibration: the block's cameras are in different models");
  options.free_interior =
      triangulation::ParseSelfCalibration(auto_free ? "all" : self_calibration, model);
  options.Validate();
  if (!block.project.rigs.empty()) return AdjustRigBlock(block, auto_free, options, kw);
  RigRequestFromKeywords(kw, false);
  const auto progress = CallbackProgress(progress_callback,
                                         "adjust",
                                         auto_free && !options.free_interior.empty()
                                             ? triangulation::AutoFreeSetRounds(options)
                                             : triangulation::AdjustStages(options));
  Result out;
  out.kept = std::make_shared<Kept>();
  {
    py::gil_scoped_release release;
    const triangulation::ObjectFrame frame(block.project.frame);
    const Project project = triangulation::ToAdjustmentFrame(block.project, frame);
    triangulation::KeptAdjustment* keep = &out.kept->adjustment;
    out.result =
        auto_free && !options.free_interior.empty()
            ? triangulation::AdjustWithChosenFreeSet(project, options, {}, progress.get(), keep)
            : triangulation::Adjust(project, options, progress.get(), keep);
    triangulation::ToInputFrame(frame, &out.result);
  }
  nlohmann::json json = triangulation::AdjustmentToJson(out.result);
  json["project"] = block.path;
  if (!block.path.empty()) tools::AddProjectFacts(block.project, &json);  // read from files
  json["valid"] = out.result.valid;
  json["invalid_reasons"] = out.result.invalid_reasons;
  out.json = ResultText("adjust", json);
  return out;
}

// The rig heads of a rig result, each {id, reference, estimated, sigma (by the head model's
// parameter names; None where unknown), mount_deg, lever_arm_m, time_offset_ms (each a mounted
// block {mode, value, sigma})}: the result file's `rig.heads` with the frame cameras' names for
// the interior.
py::list RigHeads(const Result& r) {
  py::list heads;
  if (r.rig.is_null()) return heads;
  for (nlohmann::json h : r.rig.at("heads")) {
    h["estimated"] = h.at("interior");
    h["sigma"] = h.at("interior_sigma");
    h.erase("interior");
    h.erase("interior_sigma");
    heads.append(JsonToPython(h.dump()));
  }
  return heads;
}

py::dict ParamDict(const triangulation::CameraEstimate& c,
                   const calib::InteriorParams& values,
                   bool sigma) {
  py::dict d;
  const auto table = calib::CameraModelParams(c.model);
  for (size_t k = 0; k < table.size(); ++k) {
    const std::string name(table[k].name);
    if (sigma && !(c.free[k] && values[k] > 0))
      d[py::str(name)] = py::none();  // fixed or unknown: null, never 0
    else
      d[py::str(name)] = values[k];
  }
  return d;
}

py::dict ResidualTable(const AdjustmentResult& r) {
  const size_t n = r.residuals.size();
  std::vector<std::string> image(n), point(n);
  Eigen::MatrixX2d measured(n, 2), residual(n, 2), w(n, 2), redundancy(n, 2);
  py::array_t<bool> used(static_cast<py::ssize_t>(n));
  auto used_out = used.mutable_unchecked<1>();
  for (size_t i = 0; i < n; ++i) {
    const auto& v = r.residuals[i];
    image[i] = v.image;
    point[i] = v.point;
    measured.row(i) = v.measured_px;
    residual.row(i) = v.residual_px;
    used_out(static_cast<py::ssize_t>(i)) = v.used;
    w.row(i) = v.test.tested ? v.test.w : Eigen::Vector2d::Constant(std::nan(""));
    redundancy.row(i) = v.test.tested ? v.test.redundancy : Eigen::Vector2d::Constant(std::nan(""));
  }
  py::dict d;
  d["image"] = image;
  d["point"] = point;
  d["measured_px"] = measured;
  d["residual_px"] = residual;
  d["used"] = used;
  d["w"] = w;
  d["redundancy"] = redundancy;
  return d;
}

// The adjusted points (two rays or control) in the result's frame, sorted by id: {point, xyz_m}.
py::dict AdjustedPoints(const AdjustmentResult& r) {
  std::vector<std::string> id;
  Eigen::MatrixX3d xyz(r.points_m.size(), 3);
  for (const auto& [point, p] : r.points_m) {
    xyz.row(static_cast<Eigen::Index>(id.size())) = p;
    id.push_back(point);
  }
  return py::dict(py::arg("point") = id, py::arg("xyz_m") = xyz);
}

// The exposures as the result file's `exposures`: {image, used, center_m, opk_deg, sigma_center_m,
// sigma_opk_deg}, sigmas NaN where unknown (left out, no covariance, gimbal lock).
py::dict AdjustedExposures(const AdjustmentResult& r) {
  const size_t n = r.exposures.size();
  std::vector<std::string> image(n);
  std::vector<bool> used(n);
  Eigen::MatrixX3d center(n, 3), opk(n, 3), center_sigma(n, 3), opk_sigma(n, 3);
  const double nan = std::nan("");
  for (size_t i = 0; i < n; ++i) {
    const auto& e = r.exposures[i];
    image[i] = e.image;
    used[i] = e.used;
    center.row(i) = e.center_m;
    opk.row(i) = e.opk_rad / kDegToRad;
    center_sigma.row(i) = e.center_sigma_m.value_or(Eigen::Vector3d::Constant(nan));
    opk_sigma.row(i) = e.opk_sigma_rad.value_or(Eigen::Vector3d::Constant(nan)) / kDegToRad;
  }
  return py::dict(py::arg("image") = image,
                  py::arg("used") = used,
                  py::arg("center_m") = center,
                  py::arg("opk_deg") = opk,
                  py::arg("sigma_center_m") = center_sigma,
                  py::arg("sigma_opk_deg") = opk_sigma);
}

// sigma0^2 Q of the named interior entries, Sigma = S R S with S = diag(sigma): the result's
// a-posteriori sigmas and its correlation matrix R (both from the same covariance estimate; a
// fixed entry has a zero row). `names`: entries "camera ID.NAME" or whole cameras
// "camera ID" (expanded in the model's parameter order). Exposures and points: Covariance below.
Eigen::MatrixXd InteriorCovariance(const AdjustmentResult& r,
                                   const std::vector<std::string>& names) {
  if (r.interior_correlation_names.empty())
    throw ConfigError("covariance: the adjustment has no covariance (see invalid_reasons)");
  std::map<std::string, double> sigma;
  for (const auto& c : r.cameras) {
    const auto table = calib::CameraModelParams(c.model);
    for (size_t k = 0; k < table.size(); ++k)
      sigma["camera " + c.id + "." + std::string(table[k].name)] = c.free[k] ? c.sigma[k] : 0.0;
  }
  std::vector<int> rows;
  std::vector<double> s;
  for (const auto& name : names) {
    const size_t before = rows.size();
    for (size_t i = 0; i < r.interior_correlation_names.size(); ++i) {
      const std::string& entry = r.interior_correlation_names[i];
      if (entry == name || entry.rfind(name + ".", 0) == 0) {
        rows.push_back(static_cast<int>(i));
        s.push_back(sigma.count(entry) ? sigma.at(entry) : 0.0);
      }
    }
    if (rows.size() == before)
      throw ConfigError("covariance: '" + name + "' names no interior entry (correlation_names)");
  }
  Eigen::MatrixXd out(rows.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i)
    for (size_t k = 0; k < rows.size(); ++k)
      // One triangle of R: the matrix is exactly symmetric, as a covariance must be.
      out(i, k) = (i == k ? 1.0
                          : r.interior_correlation(std::min(rows[i], rows[k]),
                                                   std::max(rows[i], rows[k]))) *
                  (s[i] * s[k]);
  return out;
}

// covariance(names): interior names alone from the result's own sigmas and correlation (the
// numbers of the JSON); with an exposure or a point, the joint matrix from the kept adjustment
// (CovarianceOfNamed: every pair of the named blocks), the GIL released while it is computed.
Eigen::MatrixXd Covariance(const Result& r, const std::vector<std::string>& names) {
  const bool interior_only = std::all_of(
      names.begin(), names.end(), [](const std::string& n) { return n.rfind("camera ", 0) == 0; });
  if (interior_only) return InteriorCovariance(r.result, names);
  if (!r.kept || !r.kept->adjustment.adjustment) {
    for (const auto& name : names)
      if (name.rfind("camera ", 0) != 0)
        throw ConfigError("covariance: '" + name +
                          "': a rig block's result keeps the interior covariance only");
  }
  if (!r.result.determinability.covariance_ok)
    throw ConfigError("covariance: the adjustment has no covariance (see invalid_reasons)");
  py::gil_scoped_release release;
  const std::lock_guard<std::mutex> lock(r.kept->mutex);
  return triangulation::CovarianceOfNamed(*r.kept->adjustment.adjustment, r.result, names).matrix;
}

// Block: a project read from files or built from arrays, and its tables.
void BindBlock(py::module_& m) {
  py::class_<Block>(m, "Block", R"doc(
A block for aerial triangulation: cameras, exposures, ground points, image observations.

Block.read(project) reads a project YAML or folder (the files of `aerocal adjust --project`);
Block.from_arrays(...) builds one from dicts of columns. The tables come back as dicts of numpy
arrays (exposures, points, observations).)doc")
      .def_static(
          "read",
          [](const std::string& path, double sigma_px) {
            Block b;
            b.project = triangulation::ReadProject(path, sigma_px);
            b.path = path;
            return b;
          },
          py::arg("path"),
          py::arg("sigma_px") = 0.5,
          "Reads a project YAML (or a folder with project.yaml); sigma_px where observations.csv "
          "has none. Bad files raise InputError naming FILE:LINE.")
      .def_static(
          "from_arrays",
          &BlockFromArrays,
          py::arg("cameras"),
          py::arg("exposures"),
          py::arg("points"),
          py::arg("observations"),
          py::arg("frame") = "as given",
          "cameras: {id: Camera}; exposures: {image, camera, X, Y, Z, omega, phi, kappa "
          "(deg)}; points: {point, X, Y, Z, sX, sY, sZ, role}; observations: {image, point, "
          "col, row, sigma_px}: each a dict of equal-length sequences.")
      .def_property_readonly("exposures", [](const Block& b) { return ExposureTable(b.project); })
      .def_property_readonly("points", [](const Block& b) { return PointTable(b.project); })
      .def_property_readonly("observations",
                             [](const Block& b) { return ObservationTable(b.project); })
      .def_property_readonly("cameras", [](const Block& b) {
        std::vector<std::string> ids;
        for (const auto& [id, c] : b.project.cameras) ids.push_back(id);
        return ids;
      });
}

void BindCameraEstimate(py::module_& m) {
  py::class_<triangulation::CameraEstimate>(m, "CameraEstimate")
      .def_readonly("id", &triangulation::CameraEstimate::id)
      .def_property_readonly("model",
                             [](const triangulation::CameraEstimate& c) {
                               return std::string(calib::CameraModelName(c.model));
                             })
      .def_property_readonly(
          "initial",
          [](const triangulation::CameraEstimate& c) { return ParamDict(c, c.initial, false); })
      .def_property_readonly(
          "estimated",
          [](const triangulation::CameraEstimate& c) { return ParamDict(c, c.estimated, false); })
      .def_property_readonly(
          "sigma",
          [](const triangulation::CameraEstimate& c) { return ParamDict(c, c.sigma, true); },
          "Standard deviations; None for fixed or unknown (never 0)");
}

// AdjustmentResult's statistics: sigma0, validity, findings, cameras, rig heads, RMSEs and the
// interior correlation.
void BindResultStatistics(py::class_<Result>& result) {
  result.def_property_readonly("sigma0", [](const Result& r) { return r.result.sigma0; })
      .def_property_readonly("sigma0_px", [](const Result& r) { return r.result.sigma0_px; })
      .def_property_readonly("converged", [](const Result& r) { return r.result.converged(); })
      .def_property_readonly("valid", [](const Result& r) { return r.result.valid; })
      .def_property_readonly("invalid_reasons",
                             [](const Result& r) { return r.result.invalid_reasons; })
      .def_property_readonly("warnings",
                             [](const Result& r) {  // the result JSON's findings
                               return JsonToPython(FindingsToJson(r.result.warnings).dump());
                             })
      .def_property_readonly("notes", [](const Result& r) { return r.result.notes; })
      .def_property_readonly("cameras", [](const Result& r) { return r.result.cameras; })
      .def_property_readonly(
          "heads",
          &RigHeads,
          "A rig block's heads (rig file order): dicts {id, reference, estimated, sigma (by "
          "parameter name; None where unknown), mount_deg, lever_arm_m, time_offset_ms (each "
          "{mode, value, sigma}: fixed, free or weighted, sigma None where held or unknown)}; [] "
          "for frame cameras")
      .def_property_readonly(
          "rig",
          [](const Result& r) {
            return r.rig.is_null() ? py::object(py::none()) : JsonToPython(r.rig.dump());
          },
          "A rig block's `rig` section of the result file (heads, options, determinability); "
          "None for frame cameras")
      .def_property_readonly(
          "check_rmse_m",
          [](const Result& r) { return Eigen::Vector3d(r.result.check.rmse_m); },
          "Check-point RMSE per axis X, Y, Z (m)")
      .def_property_readonly(
          "control_rmse_m",
          [](const Result& r) { return Eigen::Vector3d(r.result.control.rmse_m); })
      .def_property_readonly(
          "correlation",
          [](const Result& r) { return Eigen::MatrixXd(r.result.interior_correlation); },
          "Correlation matrix of the interior parameters (rows: correlation_names)")
      .def_property_readonly("correlation_names",
                             [](const Result& r) { return r.result.interior_correlation_names; });
}

// AdjustmentResult's joint covariance, its point, exposure and residual tables and its JSON.
void BindResultTables(py::class_<Result>& result) {
  result
      .def("covariance",
           &Covariance,
           py::arg("names"),
           "The joint covariance sigma0^2 Q (numpy, symmetric) of the named entries, rows in the "
           "order of `names` expanded, cross blocks included: 'camera ID.NAME' (one interior "
           "parameter) or 'camera ID' (all, in the model's order), in the parameter table's "
           "units; 'exposure ID': X, Y, Z (m), omega, phi, kappa (deg) of that exposure; 'point "
           "ID': X, Y, Z (m) of an adjusted point. Exposures and points are in the adjustment "
           "frame (the frame of the result's sigmas: the local tangent plane for local / crs "
           "frames, the UTM zone for utm, the given one for projected), even where to_json() "
           "writes positions back in geodetic or CRS coordinates. Interior names alone come "
           "from the result's sigmas and correlation; with an exposure or a point the matrix is "
           "computed from the solved problem this result keeps (the same covariance code as the "
           "run's; the GIL is released). Fixed entries have zero rows. Raises ValueError for a "
           "name the result does not hold (unknown, or left out of the adjustment), when the "
           "result has no covariance, and for exposures and points of a rig block.")
      .def_property_readonly(
          "points",
          [](const Result& r) { return AdjustedPoints(r.result); },
          "The adjusted ground points (two rays or control), sorted by id: {point, xyz_m (N, 3)} "
          "in the result's frame (as to_json() writes coordinates)")
      .def_property_readonly(
          "exposures",
          [](const Result& r) { return AdjustedExposures(r.result); },
          "The exposures as the result file's: {image, used, center_m (N, 3), opk_deg (N, 3), "
          "sigma_center_m, sigma_opk_deg (N, 3; NaN where unknown)}")
      .def_property_readonly(
          "residuals",
          [](const Result& r) { return ResidualTable(r.result); },
          "Per observation: image, point, measured_px, residual_px (N, 2), "
          "used, w and redundancy (N, 2; NaN where not tested)")
      .def(
          "to_json",
          [](const Result& r) { return r.json; },
          "The result file's text, identical to `aerocal adjust --out`");
}

}  // namespace

void BindAdjust(py::module_& m) {
  BindBlock(m);
  BindCameraEstimate(m);
  py::class_<Result> result(
      m, "AdjustmentResult", "The result of adjust(): as `aerocal adjust` writes it");
  BindResultStatistics(result);
  BindResultTables(result);

  m.def("adjust",
        &Adjust,
        py::arg("block"),
        py::arg("self_calibration") = "none",
        py::arg("progress") = py::none(),
        "Bundle block adjustment as `aerocal adjust`: self_calibration none | auto | all | "
        "'c,x0,y0,K1' ...; progress: None or a callable(done, total) called after each stage "
        "(solve, data-snooping round, covariance; with auto, each round of the free-set choice); "
        "every other option of the command as a keyword (no_snooping, "
        "robust_start, no_robust_start, max_rejections, max_sigma0, min_redundancy, "
        "critical_value, no_eo_priors, no_interior_sigma, max_iterations, "
        "correlation_threshold, suspect_effect_limit; for a rig block rig_mounts, "
        "rig_lever_arms, rig_increments, rig_increment_sigma_arcsec, rig_time_offsets, "
        "rig_time_offset_sigma_ms). A block whose camera file has a rig section runs the "
        "command's rig bundle (heads and rig on the result). The GIL is released while solving. A "
        "result that did not converge or is not valid is returned with valid=False.");
}

}  // namespace aerocal::python
