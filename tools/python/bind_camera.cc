// aerocal.Camera: a camera file of any registered format (calib/camera/formats/camera_formats.h;
// the OpenCV FileStorage row registers itself from tools/camera_formats.cc, linked in),
// its parameters by the model's names (calib/camera/camera_model.h), image <-> ray for arrays of
// points, and convert_camera (calib/camera/convert_camera.h). Everything is the C++ library's.
#include "calib/camera/camera_model.h"
#include "calib/camera/convert_camera.h"
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/error.h"
#include "tools/camera_formats.h"
#include "tools/python/bindings.h"

#include <cmath>
#include <limits>
#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <string>

namespace aerocal::python {
namespace {

namespace py = pybind11;
using calib::CameraFile;

CameraFile ReadCamera(const std::string& path,
                      const std::string& format,
                      const std::optional<std::string>& camera,
                      std::optional<int> width,
                      std::optional<int> height,
                      std::optional<double> pixel_mm) {
  calib::CameraReadOptions options;
  options.camera_id = camera.value_or("");
  if (width) options.width_px = *width;
  if (height) options.height_px = *height;
  if (pixel_mm) options.pixel_size_mm = *pixel_mm;
  if (options.width_px < 0 || options.height_px < 0 || !(options.pixel_size_mm >= 0) ||
      !std::isfinite(options.pixel_size_mm))
    throw ConfigError("width, height and pixel_mm must be positive");
  return calib::ReadCameraFileAs(format, path, options);
}

void WriteCamera(const CameraFile& camera, const std::string& path, const std::string& format) {
  const calib::CameraFormat& f = calib::FindCameraFormat(format, "format");
  if (!calib::FindWritableModel(f, camera.camera.model))
    throw ConfigError(
        "format " + format + " writes " + calib::WritableModelNames(f) +
        " cameras: convert_camera(camera, model=...) first, and look at its residual");
  calib::WriteCameraFileVerified(f, path, camera);
}

py::dict ParamsDict(const CameraFile& c) {
  py::dict out;
  const auto table = calib::CameraModelParams(c.camera.model);
  for (size_t k = 0; k < table.size(); ++k)
    out[py::str(std::string(table[k].name))] = c.camera.params[k];
  return out;
}

py::dict UnitsDict(const CameraFile& c) {
  py::dict out;
  for (const auto& p : calib::CameraModelParams(c.camera.model))
    out[py::str(std::string(p.name))] = std::string(p.unit);
  return out;
}

// Standard deviations from the file's covariance; None where the file gives none.
py::dict SigmaDict(const CameraFile& c) {
  py::dict out;
  const auto table = calib::CameraModelParams(c.camera.model);
  for (size_t k = 0; k < table.size(); ++k) {
    const std::string name(table[k].name);
    if (c.covariance && c.covariance->rows() == static_cast<int>(table.size()))
      out[py::str(name)] = std::sqrt((*c.covariance)(k, k));
    else
      out[py::str(name)] = py::none();
  }
  return out;
}

void SetParam(CameraFile& c, const std::string& name, double value) {
  const auto table = calib::CameraModelParams(c.camera.model);
  for (size_t k = 0; k < table.size(); ++k)
    if (table[k].name == name) {
      if (!std::isfinite(value)) throw ConfigError(name + " must be finite");
      c.camera.params[k] = value;
      return;
    }
  throw ConfigError("'" + name + "' is not a parameter of " +
                    std::string(calib::CameraModelName(c.camera.model)) +
                    " (its parameters: " + calib::JoinParamNames(table) + ")");
}

using Points = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Maps every row of a (N, 2) array through `map` (false: the row is NaN), the GIL released.
template <typename Map>
Points MapRows(const Points& points, const char* what, Map map) {
  if (points.ndim() != 2 || points.shape(1) != 2)
    throw ConfigError(std::string(what) + " must be an array of shape (N, 2)");
  const auto n = points.shape(0);
  Points out({n, static_cast<py::ssize_t>(2)});
  auto in = points.unchecked<2>();
  auto o = out.mutable_unchecked<2>();
  py::gil_scoped_release release;
  for (py::ssize_t i = 0; i < n; ++i) {
    Eigen::Vector2d to;
    const bool ok = map(Eigen::Vector2d(in(i, 0), in(i, 1)), &to);
    o(i, 0) = ok ? to.x() : std::numeric_limits<double>::quiet_NaN();
    o(i, 1) = ok ? to.y() : std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

// Pixels (col, row) -> normalised rays (x / c, y / c): the ray (x / c, y / c, -1) in the camera
// frame (photo x right, y up, looking along -z); NaN where the model's inversion fails.
Points ImageToRay(const CameraFile& c, const Points& pixels) {
  const double cmm = c.camera.PrincipalDistanceMm();
  return MapRows(pixels, "pixels", [&](const Eigen::Vector2d& pixel, Eigen::Vector2d* ray) {
    const bool ok = c.camera.IdealFromPixel(pixel, ray);
    *ray /= cmm;
    return ok;
  });
}

// Normalised rays (x / c, y / c) -> measured pixels (col, row); NaN where the inversion fails.
Points RayToImage(const CameraFile& c, const Points& rays) {
  const double cmm = c.camera.PrincipalDistanceMm();
  return MapRows(rays, "rays", [&](const Eigen::Vector2d& ray, Eigen::Vector2d* pixel) {
    return c.camera.PixelFromIdeal(ray * cmm, pixel);
  });
}

py::dict ResidualDict(const calib::ConversionResult& r) {
  py::dict d;
  d["exact"] = r.exact;
  d["rms_px"] = r.residual.rms_px;
  d["max_px"] = r.residual.max_px;
  d["max_at_px"] = py::make_tuple(r.residual.max_at_px.x(), r.residual.max_at_px.y());
  d["max_inner80_px"] = r.residual.max_inner80_px;
  d["points"] = r.residual.points;
  d["failed_points"] = r.residual.failed_points;
  d["fit_iterations"] = r.fit_iterations;
  d["summary"] = r.Summary();
  return d;
}

py::tuple ConvertCamera(const CameraFile& c,
                        const std::string& model,
                        const std::vector<std::string>& zero,
                        double max_residual_px) {
  const auto id = calib::CameraModelFromName(model);
  if (!id)
    throw ConfigError("model '" + model + "' is not registered (" + calib::CameraModelNames() +
                      ")");
  calib::ConvertOptions options;
  options.zero = zero;
  options.max_residual_px = max_residual_px;
  calib::FileConversion converted;
  {
    py::gil_scoped_release release;
    converted = calib::ConvertCameraFile(c, calib::FormatTarget{*id, zero, false, false}, options);
  }
  return py::make_tuple(converted.file, ResidualDict(converted.result));
}

// Camera: reading and writing, the parameters and the frame.
void BindCameraFile(py::class_<CameraFile>& camera) {
  camera
      .def_static(
          "read",
          &ReadCamera,
          py::arg("path"),
          py::arg("format") = "auto",
          py::arg("camera") = py::none(),
          py::arg("width") = py::none(),
          py::arg("height") = py::none(),
          py::arg("pixel_mm") = py::none(),
          "Reads a camera file (any format of formats(); 'auto' detects it). `camera` picks "
          "one camera of a file holding several; width/height/pixel_mm complete a file "
          "that lacks them. Bad files raise InputError (a ValueError) naming FILE:LINE.")
      .def("write",
           &WriteCamera,
           py::arg("path"),
           py::arg("format") = "aerocal",
           "Writes the camera in `format` (atomically, verified by the format's own reader).")
      .def_property_readonly("name", [](const CameraFile& c) { return c.name; })
      .def_property_readonly(
          "model",
          [](const CameraFile& c) { return std::string(calib::CameraModelName(c.camera.model)); })
      .def_property_readonly(
          "params", &ParamsDict, "Parameters by name (a copy; set with set_param)")
      .def_property_readonly("units", &UnitsDict)
      .def_property_readonly("sigma", &SigmaDict)
      .def_property_readonly("width", [](const CameraFile& c) { return c.camera.frame.width_px; })
      .def_property_readonly("height", [](const CameraFile& c) { return c.camera.frame.height_px; })
      .def_property_readonly("pixel_size_mm",
                             [](const CameraFile& c) -> py::object {
                               if (!c.pixel_size_known) return py::none();
                               return py::float_(c.camera.frame.pixel_size_mm);
                             })
      .def_property_readonly("principal_distance_mm",
                             [](const CameraFile& c) { return c.camera.PrincipalDistanceMm(); })
      .def_property_readonly(
          "principal_distance_px",
          [](const CameraFile& c) {
            return c.camera.PrincipalDistanceMm() / c.camera.frame.pixel_size_mm;
          },
          "The principal distance in pixels: known even where the file gives no pixel size "
          "(a camera in pixel units)")
      .def_property_readonly(
          "notes",
          [](const CameraFile& c) { return c.notes; },
          "What the reader assumed or left out")
      .def("set_param", &SetParam, py::arg("name"), py::arg("value"));
}

// Camera: pixels to rays and back.
void BindCameraProjection(py::class_<CameraFile>& camera) {
  camera
      .def("image_to_ray",
           &ImageToRay,
           py::arg("pixels"),
           "pixels[N, 2] (col, row) -> rays[N, 2] (x / c, y / c); NaN where the model's "
           "inversion does not converge")
      .def("ray_to_image",
           &RayToImage,
           py::arg("rays"),
           "rays[N, 2] (x / c, y / c) -> pixels[N, 2] (col, row)")
      .def("__repr__", [](const CameraFile& c) {
        return "<aerocal.Camera " + c.name + " " +
               std::string(calib::CameraModelName(c.camera.model)) + " " +
               std::to_string(c.camera.frame.width_px) + "x" +
               std::to_string(c.camera.frame.height_px) + ">";
      });
}

// The registries: conversion between models, the file formats and the models.
void BindCameraRegistry(py::module_& m) {
  m.def("convert_camera",
        &ConvertCamera,
        py::arg("camera"),
        py::arg("model"),
        py::arg("zero") = std::vector<std::string>{},
        py::arg("max_residual_px") = std::numeric_limits<double>::infinity(),
        "The camera expressed in another registered model: (Camera, residual dict with exact, "
        "rms_px, max_px, max_at_px, max_inner80_px, points, failed_points, summary). Exact where "
        "the models are equivalent, else a least-squares fit over the format. `zero`: parameters "
        "of the target held at 0.");
  m.def(
      "formats",
      [] {
        std::vector<std::string> names;
        for (const auto& f : calib::CameraFormats()) names.push_back(f.name);
        return names;
      },
      "Names of the camera file formats (the registry)");
  m.def(
      "models",
      [] {
        std::vector<std::string> names;
        calib::ForEachCameraModel([&](auto model) { names.emplace_back(decltype(model)::kName); });
        return names;
      },
      "Names of the registered camera models");
}

}  // namespace

void BindCamera(py::module_& m) {
  py::class_<CameraFile> camera(m, "Camera", R"doc(
A camera in any registered model, as a camera file holds it.

Read one with Camera.read(path, format="auto"); `format` is any name of formats() ("auto" detects
it from the content). Parameters are a dict by the model's names in its units (camera.units);
camera.sigma holds the file's standard deviations (None where it gives none). Pixels are
(col, row) with the top-left pixel centre at (0, 0); rays are normalised (x / c, y / c) in the
photo frame (x right, y up), the camera looking along -z.)doc");
  BindCameraFile(camera);
  BindCameraProjection(camera);
  BindCameraRegistry(m);
}

}  // namespace aerocal::python
