#pragma once
// basalt._core, the compiled part of the Python package basalt (docs/python.md): one bind_xxx(module) per
// source file, each called once from module.cpp. A new part (e.g. the simulation) is one more file here, one
// line in module.cpp and one in python/CMakeLists.txt. The pure-Python package (python/basalt/) wraps these
// functions; users call basalt.read_geometry, basalt.pack.box ..., never _core directly.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "basalt/io/geometry.hpp"

//
// Threads: the packer runs without the GIL (other Python threads go on); every call that may reach HDF5 keeps
// it, since Debian's parallel HDF5 is built without thread safety: two Python threads reading at once would
// enter it together. (h5py links a separate, serial HDF5 with its own lock.)

namespace basalt::python {

/// C++ errors as Python exceptions (basalt._errors): io::FormatError -> basalt.FormatError, packer::PackError
/// -> basalt.PackError (both ValueError), with the C++ message unchanged.
void bind_errors(pybind11::module_& m);
/// read_geometry, write_geometry: the I/O layer's geometry formats (.h5 and ESyS-Particle's .geo).
void bind_geometry(pybind11::module_& m);
/// check_checkpoint, latest_complete_checkpoint: basalt-run's checks of a checkpoint (the data is read by
/// h5py).
void bind_checkpoint(pybind11::module_& m);
/// pack: basalt-pack's request (packer/include/basalt/packer/request.hpp).
void bind_pack(pybind11::module_& m);
/// Simulation: a run driven from Python (solver/simulation.hpp, basalt-run's start-up and output).
void bind_simulation(pybind11::module_& m);
/// gengeo_fit: the simplex fit of the ESyS front end's GenGeo packing (python/basalt/esys/gengeo.py).
void bind_gengeo(pybind11::module_& m);
/// EsysBoxPacker, EsysStream: the ESyS front end's RandomBoxPacker (python/basalt/esys/packer.py).
void bind_esys_packer(pybind11::module_& m);
/// esys_format_rows: the ESyS front end's checkpoint rows (python/basalt/esys/output.py).
void bind_esys_format(pybind11::module_& m);

/// A geometry as the dict basalt.Geometry is built from: numpy arrays (copies) of the particles and bonds,
/// the box, units, provenance and statistics.
pybind11::dict geometry_to_dict(const basalt::io::Geometry& g);

}  // namespace basalt::python
