// basalt-pack's request for Python (basalt.pack.box ...): the same checks, messages, spheres and bonds as the
// command line, since both go through basalt::packer::prepare and run
// (packer/include/basalt/packer/request.hpp).
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "basalt/packer/error.hpp"
#include "basalt/packer/request.hpp"
#include "basalt/version.hpp"
#include "bindings.hpp"

namespace py = pybind11;
namespace packer = basalt::packer;

namespace basalt::python {

namespace {

packer::Shape parse_shape(const std::string& shape) {
  if (shape == "box") return packer::Shape::box;
  if (shape == "cylinder") return packer::Shape::cylinder;
  if (shape == "sphere") return packer::Shape::sphere;
  if (shape == "mesh") return packer::Shape::mesh;
  throw py::value_error("unknown shape '" + shape + "': box, cylinder, sphere or mesh");
}

py::dict stats_dict(const packer::PackResult& r, const std::string& volume) {
  const auto& st = r.stats;
  py::dict d;
  d["volume"] = volume;
  d["particles"] = st.particles;
  d["solid_fraction"] = st.solid_fraction;
  d["min_radius"] = st.min_radius;
  d["max_radius"] = st.max_radius;
  d["fitted_exponent"] = st.histogram.exponent;
  d["histogram_edges"] = st.histogram.edges;
  d["histogram_counts"] = st.histogram.counts;
  d["bonds"] = st.bonds;
  d["bonds_per_particle"] = st.bonds_per_particle;
  d["mean_coordination"] = st.mean_coordination;
  d["largest_overlap"] = st.largest_overlap;
  d["largest_boundary_overlap"] = std::max(0.0, st.largest_boundary_overlap);
  d["radii_drawn"] = r.requested;
  d["radii_not_placed"] = r.not_placed;
  d["note"] = r.low.text;
  d["far_below"] = r.low.far_below;
  return d;
}

}  // namespace

void bind_pack(py::module_& m) {
  // The request's defaults, which basalt.pack's keyword defaults must equal (tests/python/test_pack.py).
  m.def("pack_defaults", [] {
    const packer::Request r;
    py::dict d;
    d["origin"] = r.origin;
    d["centre"] = r.centre;
    d["seed"] = r.seed;
    d["exponent"] = r.pack.exponent;
    d["target_fraction"] = r.pack.target_fraction;
    d["fill"] = r.pack.fill_after;
    d["bond_tolerance"] = r.assembly.bond_tolerance;
    d["no_bonds"] = r.no_bonds;
    d["lattice"] = r.lattice;
    d["bond_tag"] = r.assembly.bond_tag;
    d["overlap_tolerance"] = r.pack.overlap_tolerance;
    d["seed_fraction"] = r.pack.seed_fraction;
    d["bins"] = r.assembly.histogram_bins;
    d["max_spheres"] = r.max_spheres;
    d["allow_large"] = r.allow_large;
    d["allow_low_fraction"] = r.allow_low_fraction;
    return d;
  });
  m.def(
      "pack",
      [](const std::string& shape, double rmin, double rmax, const std::string& size,
         const std::string& origin, const std::string& centre, double radius, double height,
         const std::string& mesh_file, const std::string& seed, std::optional<double> exponent,
         double target_fraction, bool fill, double bond_tolerance, bool no_bonds, bool lattice,
         std::int32_t bond_tag, double overlap_tolerance, const std::vector<std::string>& tag_layer,
         double seed_fraction, int bins, std::optional<int> threads, double max_spheres, bool allow_large,
         bool allow_low_fraction, const std::string& output) {
        packer::Request r;
        r.shape = parse_shape(shape);
        r.size = size;
        r.origin = origin;
        r.centre = centre;
        r.radius = radius;
        r.height = height;
        r.mesh_file = mesh_file;
        r.seed = seed;
        r.pack.rmin = rmin;
        r.pack.rmax = rmax;
        r.pack.exponent = exponent;
        r.pack.target_fraction = target_fraction;
        r.pack.fill_after = fill;
        r.pack.overlap_tolerance = overlap_tolerance;
        r.pack.seed_fraction = seed_fraction;
        r.assembly.bond_tolerance = bond_tolerance;
        r.assembly.bond_tag = bond_tag;
        r.assembly.histogram_bins = bins;
        // None: the machine's cores, as basalt-pack's default; the spheres do not depend on it.
        r.assembly.threads =
            threads ? *threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
        r.tag_layers = tag_layer;
        r.no_bonds = no_bonds;
        r.lattice = lattice;
        r.max_spheres = max_spheres;
        r.allow_large = allow_large;
        r.allow_low_fraction = allow_low_fraction;
        r.output = output;
        packer::PackResult result;
        std::string volume;
        {
          py::gil_scoped_release release;  // the packer touches no HDF5 (bindings.hpp)
          auto prepared = packer::prepare(r);
          volume = prepared.volume->description();
          result = packer::run(prepared);
        }
        return py::make_tuple(geometry_to_dict(result.geometry), stats_dict(result, volume));
      },
      py::kw_only(), py::arg("shape"), py::arg("rmin"), py::arg("rmax"), py::arg("size"), py::arg("origin"),
      py::arg("centre"), py::arg("radius"), py::arg("height"), py::arg("mesh_file"), py::arg("seed"),
      py::arg("exponent").none(true), py::arg("target_fraction"), py::arg("fill"), py::arg("bond_tolerance"),
      py::arg("no_bonds"), py::arg("lattice"), py::arg("bond_tag"), py::arg("overlap_tolerance"),
      py::arg("tag_layer"), py::arg("seed_fraction"), py::arg("bins"), py::arg("threads").none(true),
      py::arg("max_spheres"), py::arg("allow_large"), py::arg("allow_low_fraction"), py::arg("output"),
      "basalt-pack's request (options as on its command line, vectors and the seed as text): returns "
      "(geometry "
      "dict, statistics dict) without provenance (every argument given: basalt.pack holds the defaults); "
      "errors raise basalt.PackError with basalt-pack's message. "
      "Use basalt.pack.box, cylinder, sphere or mesh.");
  m.attr("pack_creator") = std::string("basalt-pack ") + basalt::kVersion;
}

}  // namespace basalt::python
