// aerocal.resample: the virtual image of one frame as `aerocal resample` makes it (the same
// reading and checks, tools/resample_frame.h), returned as a numpy array and, with `out`, written
// as the command's TIFF.
#include "calib/core/atomic_file.h"
#include "stitch/resample/tiff_raster.h"
#include "tools/python/bindings.h"
#include "tools/resample_frame.h"

#include <cstring>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

namespace aerocal::python {
namespace {

namespace py = pybind11;

py::array Resample(const std::string& camera,
                   const std::string& mapping,
                   const py::object& images,
                   const std::string& frame,
                   const std::string& interpolation,
                   double fill,
                   const std::string& out) {
  if (!out.empty()) CheckOutputFile(out, "out");
  tools::ResampleRequest request;
  request.camera = camera;
  request.mapping = mapping;
  request.frame = frame;
  request.images = ImagesOptionText(images);
  request.interpolation = interpolation;
  request.fill = fill;
  tools::PreparedResample p = tools::PrepareResample(request);
  stitch::MemoryRaster raster(p.virtual_info);
  {
    py::gil_scoped_release release;
    stitch::ResampleVirtualImage(p.camera, p.sources, &raster, p.options);
    if (!out.empty()) {  // the command's file: the same rows through the same writer
      stitch::TiffWriteOptions tiff;
      tiff.description = p.description;
      stitch::TiffWriter writer(out, p.virtual_info, tiff);
      writer.WriteRows(0, p.virtual_info.height, raster.bytes().data());
      writer.Commit();
    }
  }
  return RasterToNumpy(raster);
}

template <typename T>
py::array Pixels(const stitch::MemoryRaster& raster) {
  const stitch::RasterInfo info = raster.Info();
  std::vector<py::ssize_t> shape = {info.height, info.width};
  if (info.bands > 1) shape.push_back(info.bands);
  py::array_t<T> out(shape);
  std::memcpy(out.mutable_data(), raster.bytes().data(), raster.bytes().size());
  return out;
}

}  // namespace

py::array RasterToNumpy(const stitch::MemoryRaster& raster) {
  return raster.Info().bits == 8 ? Pixels<std::uint8_t>(raster) : Pixels<std::uint16_t>(raster);
}

std::string ImagesOptionText(const py::object& images) {
  if (images.is_none()) return "";
  if (py::isinstance<py::str>(images)) return images.cast<std::string>();
  std::string text;
  for (const auto& [id, path] : images.cast<py::dict>())
    text += (text.empty() ? "" : ",") + py::str(id).cast<std::string>() + "=" +
            py::str(path).cast<std::string>();
  return text;
}

py::object JsonToPython(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

void BindResample(py::module_& m) {
  m.def("resample",
        &Resample,
        py::arg("camera"),
        py::arg("mapping"),
        py::arg("images"),
        py::arg("frame") = "",
        py::arg("interpolation") = "bilinear",
        py::arg("fill") = 0.0,
        py::arg("out") = "",
        "The virtual image of one frame as `aerocal resample --camera CAMERA --mapping MAPPING "
        "--images ...` makes it: images {sub-image id: file} (or the option's 'I=a.tif,...' "
        "text), frame the stitch result's frame (default: its top level), interpolation "
        "bilinear | bicubic, fill the grey value where no sub-image covers. Returns a numpy "
        "array (rows, cols[, bands]) of uint8 or uint16; out: also the command's TIFF. The GIL "
        "is released while resampling.");
}

}  // namespace aerocal::python
