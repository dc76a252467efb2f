// The I/O layer's geometry reader and writer for Python: one parser of .h5 and .geo for the tools and the
// package, with the same checks and the same messages (file and line, or file and dataset).
#include <pybind11/stl.h>

#include <cstring>
#include <string>

#include "bindings.hpp"

namespace py = pybind11;
namespace io = basalt::io;

namespace basalt::python {

namespace {

template <class T>
py::array_t<T> column(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

py::array_t<double> rows3(const std::vector<io::Vec3>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(io::Vec3));
  return a;
}

py::array_t<double> vec3(const io::Vec3& v) {
  py::array_t<double> a(3);
  std::memcpy(a.mutable_data(), v.data(), sizeof(io::Vec3));
  return a;
}

// Arrays from Python: C order, of the element type (numpy converts safely, e.g. int32 to int64, and refuses
// unsafe casts such as float ids).
using Ids = py::array_t<std::int64_t, py::array::c_style>;
using Tags = py::array_t<std::int32_t, py::array::c_style>;
using Reals = py::array_t<double, py::array::c_style>;

void check_shape(const py::array& a, const char* name, py::ssize_t rows, py::ssize_t cols) {
  const bool ok = cols == 0 ? (a.ndim() == 1 && (rows < 0 || a.shape(0) == rows))
                            : (a.ndim() == 2 && (rows < 0 || a.shape(0) == rows) && a.shape(1) == cols);
  if (ok) return;
  std::string shape = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
  shape += a.ndim() == 1 ? ",)" : ")";
  const std::string want = (rows < 0 ? std::string("N") : std::to_string(rows)) +
                           (cols == 0 ? std::string(",") : ", " + std::to_string(cols));
  throw py::value_error(std::string(name) + ": shape " + shape + ", expected (" + want + ")");
}

io::Vec3 to_vec3(const Reals& a, const char* name) {
  check_shape(a, name, 3, 0);
  return {a.at(0), a.at(1), a.at(2)};
}

io::Geometry geometry_from(const Ids& id, const Reals& position, const Reals& radius, const Tags& tag,
                           const std::optional<Reals>& mass, const Ids& pairs, const Tags& bond_tag,
                           const Reals& box_min, const Reals& box_max, const std::array<bool, 3>& periodic,
                           const std::map<std::string, std::string>& units,
                           const std::map<std::string, std::string>& attributes,
                           const std::map<std::string, Reals>& statistics) {
  const py::ssize_t n = id.ndim() == 1 ? id.shape(0) : -1;
  check_shape(id, "particles[\"id\"]", -1, 0);
  check_shape(position, "particles[\"position\"]", n, 3);
  check_shape(radius, "particles[\"radius\"]", n, 0);
  check_shape(tag, "particles[\"tag\"]", n, 0);
  if (mass) check_shape(*mass, "particles[\"mass\"]", n, 0);
  check_shape(pairs, "bonds[\"pairs\"]", -1, 2);
  check_shape(bond_tag, "bonds[\"tag\"]", pairs.shape(0), 0);
  io::Geometry g;
  const auto un = static_cast<std::size_t>(n);
  g.id.assign(id.data(), id.data() + un);
  g.position.resize(un);
  if (n > 0) std::memcpy(g.position.data(), position.data(), un * sizeof(io::Vec3));
  g.radius.assign(radius.data(), radius.data() + un);
  g.tag.assign(tag.data(), tag.data() + un);
  if (mass) g.mass.assign(mass->data(), mass->data() + un);
  const auto m = static_cast<std::size_t>(pairs.shape(0));
  g.bonds.resize(m);
  for (std::size_t k = 0; k < m; ++k)
    g.bonds[k] = {pairs.data()[2 * k], pairs.data()[2 * k + 1], bond_tag.data()[k]};
  g.box_min = to_vec3(box_min, "box_min");
  g.box_max = to_vec3(box_max, "box_max");
  g.periodic = periodic;
  for (const auto& [key, value] : units) {
    if (key == "length")
      g.units.length = value;
    else if (key == "time")
      g.units.time = value;
    else if (key == "force")
      g.units.force = value;
    else if (key == "mass")
      g.units.mass = value;
    else
      throw py::value_error("units: unknown key '" + key + "' (length, time, force, mass)");
  }
  g.attributes = attributes;
  for (const auto& [key, values] : statistics) {
    if (values.ndim() != 1) throw py::value_error("statistics['" + key + "']: not a one-dimensional array");
    g.statistics[key].assign(values.data(), values.data() + values.shape(0));
  }
  return g;
}

}  // namespace

py::dict geometry_to_dict(const io::Geometry& g) {
  py::dict d;
  d["id"] = column(g.id);
  d["position"] = rows3(g.position);
  d["radius"] = column(g.radius);
  d["tag"] = column(g.tag);
  d["mass"] = g.has_mass() ? py::object(column(g.mass)) : py::object(py::none());
  py::array_t<std::int64_t> pairs({static_cast<py::ssize_t>(g.bonds.size()), py::ssize_t{2}});
  py::array_t<std::int32_t> bond_tag(static_cast<py::ssize_t>(g.bonds.size()));
  auto* p = pairs.mutable_data();
  auto* t = bond_tag.mutable_data();
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    p[2 * k] = g.bonds[k].a;
    p[2 * k + 1] = g.bonds[k].b;
    t[k] = g.bonds[k].tag;
  }
  d["bonds"] = pairs;
  d["bond_tag"] = bond_tag;
  d["box_min"] = vec3(g.box_min);
  d["box_max"] = vec3(g.box_max);
  d["periodic"] = py::make_tuple(g.periodic[0], g.periodic[1], g.periodic[2]);
  py::dict units;
  units["length"] = g.units.length;
  units["time"] = g.units.time;
  units["force"] = g.units.force;
  units["mass"] = g.units.mass;
  d["units"] = units;
  d["attributes"] = g.attributes;
  py::dict stats;
  for (const auto& [key, values] : g.statistics) stats[py::str(key)] = column(values);
  d["statistics"] = stats;
  return d;
}

void bind_geometry(py::module_& m) {
  m.def(
      "read_geometry",
      [](const std::string& path) {
        // With the GIL held: Debian's parallel HDF5 is not thread-safe (bindings.hpp).
        return geometry_to_dict(io::read_geometry(path));
      },
      py::arg("path"),
      "Reads a geometry (.h5/.hdf5: Basalt's schema; .geo: ESyS-Particle's) with basalt-run's reader: a dict "
      "of numpy arrays. Errors raise basalt.FormatError naming the file and the line or dataset.");
  m.def(
      "write_geometry",
      [](const std::string& path, const Ids& id, const Reals& position, const Reals& radius, const Tags& tag,
         const std::optional<Reals>& mass, const Ids& bonds, const Tags& bond_tag, const Reals& box_min,
         const Reals& box_max, const std::array<bool, 3>& periodic,
         const std::map<std::string, std::string>& units,
         const std::map<std::string, std::string>& attributes,
         const std::map<std::string, Reals>& statistics) {
        io::Geometry g = geometry_from(id, position, radius, tag, mass, bonds, bond_tag, box_min, box_max,
                                       periodic, units, attributes, statistics);
        io::write_geometry(g, path);  // with the GIL held, as read_geometry
      },
      py::arg("path"), py::arg("id"), py::arg("position"), py::arg("radius"), py::arg("tag"), py::arg("mass"),
      py::arg("bonds"), py::arg("bond_tag"), py::arg("box_min"), py::arg("box_max"), py::arg("periodic"),
      py::arg("units"), py::arg("attributes"), py::arg("statistics"),
      "Writes a geometry by extension (.h5/.hdf5 or .geo) with basalt-pack's writer (atomic: a temporary "
      "name, then renamed); checks it first (FormatError naming the file and the first bad particle or "
      "bond).");
}

}  // namespace basalt::python
