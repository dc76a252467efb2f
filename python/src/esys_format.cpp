// esys_format_rows: the rows of the ESyS front end's text checkpoints (python/basalt/esys/output.py), the
// same text Python's `"%.9g ... %d ..." % row` makes, written in C++ (a checkpoint of 5,000 particles is
// 110,000 numbers; Python's % took most of the checkpoints' time). printf's %g and Python's are both
// correctly rounded and share the layout rules; Python writes every NaN as "nan" (glibc writes "-nan" for a
// negative one), and %d of a float writes int(x), its truncation.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include "bindings.hpp"

namespace basalt::python {
namespace {

namespace py = pybind11;

/// One line per row of `table` (n x m float64): the numbers separated by single spaces, each "%.9g", or "%d"
/// where `integer` holds 'd' for its column.
py::bytes esys_format_rows(const py::array_t<double, py::array::c_style | py::array::forcecast>& table,
                           const std::string& integer) {
  if (table.ndim() != 2) throw std::invalid_argument("esys_format_rows: a 2-D table");
  const auto n = static_cast<std::size_t>(table.shape(0)), m = static_cast<std::size_t>(table.shape(1));
  if (integer.size() != m)
    throw std::invalid_argument("esys_format_rows: one format letter per column (" + std::to_string(m) + ")");
  const double* v = table.data();
  std::string out;
  out.reserve(n * m * 17);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < m; ++j) {
      const double x = v[i * m + j];
      if (j > 0) out.push_back(' ');
      if (integer[j] == 'd') {
        if (!std::isfinite(x)) throw std::invalid_argument("esys_format_rows: %d of a non-finite number");
        fmt::format_to(std::back_inserter(out), "{}", static_cast<long long>(x));
      } else if (std::isnan(x)) {
        out += "nan";
      } else {
        fmt::format_to(std::back_inserter(out), "{:.9g}", x);
      }
    }
    out.push_back('\n');
  }
  return py::bytes(out);
}

}  // namespace

void bind_esys_format(py::module_& m) {
  m.def("esys_format_rows", &esys_format_rows, py::arg("table"), py::arg("columns"),
        "The ESyS front end's checkpoint rows (basalt.esys.output): one line per row of the float64 table, "
        "numbers as Python's '%.9g' (or '%d' where `columns` has 'd'), separated by spaces; bytes.");
}

}  // namespace basalt::python
