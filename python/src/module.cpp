// basalt._core: the compiled part of the Python package (bindings.hpp says how it is laid out).
#include <pybind11/pybind11.h>

#include "basalt/version.hpp"
#include "bindings.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() =
      "Basalt's compiled core: geometry formats and the packer (use the package basalt, not this module)";
  m.attr("__version__") = basalt::kVersion;
  basalt::python::bind_errors(m);
  basalt::python::bind_geometry(m);
  basalt::python::bind_checkpoint(m);
  basalt::python::bind_pack(m);
  basalt::python::bind_simulation(m);
  basalt::python::bind_gengeo(m);
  basalt::python::bind_esys_packer(m);
  basalt::python::bind_esys_format(m);
}
