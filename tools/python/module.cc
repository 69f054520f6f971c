// PYBIND11_MODULE of `aerocal._aerocal`: the errors as Python exceptions, then every area.
#include "calib/core/error.h"
#include "tools/python/bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(_aerocal, m) {
  m.doc() = "aerocal: calibration of large-format and multi-head aerial cameras (C++ core)";
  // Bad input (FILE:LINE: what) and bad options are ValueErrors, as Python users expect; the
  // classes keep aerocal's names so that scripts can tell them apart.
  static py::exception<aerocal::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<aerocal::ConfigError> config_error(m, "ConfigError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const aerocal::InputError& e) {
      input_error(e.what());
    } catch (const aerocal::ConfigError& e) {
      config_error(e.what());
    }
  });
  aerocal::python::BindCamera(m);
  aerocal::python::BindAdjust(m);
  aerocal::python::BindStitch(m);
  aerocal::python::BindResample(m);
  aerocal::python::BindCalibrate(m);
  aerocal::python::BindRig(m);
  aerocal::python::BindPushbroom(m);
  aerocal::python::BindMatch(m);
}
