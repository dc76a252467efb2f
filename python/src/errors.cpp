// Basalt's C++ errors as the Python exceptions of basalt._errors, messages unchanged.
#include "basalt/solver/core/errors.hpp"

#include <exception>

#include "basalt/io/geometry.hpp"
#include "basalt/packer/error.hpp"
#include "bindings.hpp"

namespace py = pybind11;

namespace basalt::python {

namespace {

/// Raises basalt._errors.<name>(args...) as the pending Python error; a plain ValueError with `what` when
/// that module cannot be imported (a _core loaded outside its package).
template <class... Args>
void raise(const char* name, const char* what, Args&&... args) {
  try {
    const py::object cls = py::module_::import("basalt._errors").attr(name);
    const py::object err = cls(what, std::forward<Args>(args)...);
    PyErr_SetObject(cls.ptr(), err.ptr());
  } catch (const py::error_already_set&) {
    PyErr_SetString(PyExc_ValueError, what);
  }
}

}  // namespace

void bind_errors(py::module_&) {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const basalt::io::FormatError& e) {
      raise("FormatError", e.what(), e.file().string(), e.where());
    } catch (const basalt::packer::PackError& e) {
      raise("PackError", e.what());
    } catch (const basalt::solver::InputError& e) {
      raise("InputError", e.what());
    } catch (const basalt::solver::RunError& e) {
      raise("RunError", e.what());
    }
  });
}

}  // namespace basalt::python
