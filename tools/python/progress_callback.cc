#include "tools/python/progress_callback.h"

namespace aerocal::python {

std::unique_ptr<Progress> CallbackProgress(const pybind11::object& callback,
                                           const std::string& label,
                                           long total) {
  namespace py = pybind11;
  if (callback.is_none()) return nullptr;
  if (!PyCallable_Check(callback.ptr())) throw py::type_error("progress: a callable(done, total)");
  Progress::SetEnabled(false);
  auto progress = std::make_unique<Progress>(label, total);
  progress->SetObserver([callback](long done, long all) {
    py::gil_scoped_acquire gil;
    callback(done, all);
  });
  return progress;
}

}  // namespace aerocal::python
