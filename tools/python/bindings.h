// The Python module `aerocal` (issue 32): the library's objects with numpy arrays, no second
// implementation of anything. Each Bind* adds one area's classes and functions to the module;
// tools/python/aerocal/__init__.py is the package around it (docstrings, help(aerocal)).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <string>

namespace aerocal::stitch {
class MemoryRaster;
}

namespace aerocal::python {

/// The raster's samples as a numpy array (rows, cols[, bands]) of uint8 or uint16, copied.
pybind11::array RasterToNumpy(const stitch::MemoryRaster& raster);

/// The `--images` text "I=a.tif,II=b.tif" of a {sub-image id: file} dict, the text itself, or ""
/// for None (resample, match).
std::string ImagesOptionText(const pybind11::object& images);

/// A JSON text as the Python object json.loads makes of it (the result documents' sections).
pybind11::object JsonToPython(const std::string& text);

/// Camera: read/write in any registered format, parameters by name, image <-> ray, conversion.
void BindCamera(pybind11::module_& m);
/// Block.read and Block from arrays, adjust(block, **options) -> AdjustmentResult.
void BindAdjust(pybind11::module_& m);
/// stitch(camera, observations, **options) -> StitchResult: `aerocal stitch` from Python.
void BindStitch(pybind11::module_& m);
/// resample(camera, mapping, images, ...) -> numpy array: `aerocal resample` from Python.
void BindResample(pybind11::module_& m);
/// calibrate(camera, observations=..., points=... | images=..., board=...) -> CalibrationResult.
void BindCalibrate(pybind11::module_& m);
/// rig_stitch(camera, project, ...) -> RigStitchResult: `aerocal rig stitch` from Python.
void BindRig(pybind11::module_& m);
/// pushbroom_calibrate(camera, pos, observations, points, **options) -> LineCalibrationResult.
void BindPushbroom(pybind11::module_& m);
/// match(camera, images, frame, ...) -> dict of numpy columns: `aerocal match` from Python.
void BindMatch(pybind11::module_& m);

}  // namespace aerocal::python
