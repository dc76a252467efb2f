// basalt-run's checks of a checkpoint file for Python's reader (python/basalt/checkpoint.py), which then
// reads the datasets with h5py: a file basalt-run refuses is refused with its message.
#include "basalt/io/checkpoint.hpp"

#include <pybind11/stl.h>

#include <string>

#include "basalt/io/checkpoint_rows.hpp"
#include "bindings.hpp"

namespace py = pybind11;
namespace io = basalt::io;

namespace basalt::python {

void bind_checkpoint(py::module_& m) {
  m.def(
      "check_checkpoint",
      [](const std::string& path) {
        // With the GIL held: Debian's parallel HDF5 is not thread-safe (bindings.hpp).
        const io::CheckpointFile file(path);  // schema, completion, every dataset's type and shape, clock
        const io::CheckpointHeader& h = file.header();
        py::dict d;
        d["particles"] = h.particles;
        d["bonds"] = h.bonds;
        d["contacts"] = h.contacts;
        d["particle_fields"] = h.particle_fields;
        d["step"] = h.run.step;
        return d;
      },
      py::arg("path"),
      "basalt-run's header check of a checkpoint (reads no rows); raises basalt.FormatError with its "
      "message. "
      "Returns the row counts and the step.");
  m.def(
      "latest_complete_checkpoint",
      [](const std::string& dir) { return io::latest_complete_checkpoint(dir).string(); }, py::arg("dir"),
      "The complete ckpt_<step>.h5 of `dir` with the highest step (as basalt-run --restart <dir> picks it), "
      "or '' when there is none.");
}

}  // namespace basalt::python
