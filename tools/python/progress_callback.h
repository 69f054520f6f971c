// A Progress (calib/core/progress.h) that reports to a Python callable instead of a terminal line:
// the `progress=` keyword of adjust() and stitch().
#pragma once

#include "calib/core/progress.h"

#include <memory>
#include <pybind11/pybind11.h>
#include <string>

namespace aerocal::python {

/// nullptr for None; TypeError for anything not callable. The observer calls
/// `callback(done, total)` under the GIL on the advancing thread; drawing on the terminal is
/// switched off (a notebook's stderr is no terminal line). A callback that raises stops the work:
/// the exception leaves the C++ call on this thread and reaches the caller unchanged.
std::unique_ptr<Progress> CallbackProgress(const pybind11::object& callback,
                                           const std::string& label,
                                           long total);

}  // namespace aerocal::python
