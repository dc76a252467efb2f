// basalt-pack's checks before packing and the pack itself, shared with the Python package (request.hpp).
#include "basalt/packer/request.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "basalt/packer/error.hpp"

namespace fs = std::filesystem;

namespace basalt::packer {

Vec3 parse_vec3(const std::string& text, const char* option) {
  Vec3 v{};
  std::size_t pos = 0;
  for (int k = 0; k < 3; ++k) {
    const auto end = text.find(',', pos);
    if ((k < 2) == (end == std::string::npos))
      throw PackError(
          fmt::format("{} '{}': expected three comma-separated numbers, e.g. 15,15,15", option, text));
    const std::string part = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    try {
      std::size_t used = 0;
      v[k] = std::stod(part, &used);
      if (used != part.size()) throw std::invalid_argument(part);
    } catch (const std::exception&) {
      throw PackError(fmt::format("{} '{}': '{}' is not a number", option, text, part));
    }
    pos = end + 1;
  }
  return v;
}

void check_output(const fs::path& out) {
  std::string ext = out.extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".h5" && ext != ".hdf5" && ext != ".geo")
    throw PackError(fmt::format("{}: unknown output format '{}' (use .h5 for Basalt, .geo for ESyS-Particle)",
                                out.string(), ext));
  const fs::path dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  if (!fs::is_directory(dir))
    throw PackError(
        fmt::format("{}: cannot write the output: folder '{}' does not exist", out.string(), dir.string()));
  if (fs::is_directory(out))
    throw PackError(fmt::format("{}: cannot write the output: it is a folder", out.string()));
  if (access(dir.c_str(), W_OK) != 0)
    throw PackError(
        fmt::format("{}: cannot write the output: folder '{}' is not writable", out.string(), dir.string()));
}

std::uint64_t parse_seed(const std::string& text) {
  const auto bad = [&](const char* why) {
    return PackError(fmt::format("--seed '{}': {}; give a whole number from 0 to {}", text, why,
                                 std::numeric_limits<std::uint64_t>::max()));
  };
  if (text.empty()) throw bad("empty");
  if (text[0] == '-') throw bad("a seed cannot be negative");
  for (char ch : text)
    if (ch < '0' || ch > '9') throw bad("not a whole number");
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), nullptr, 10);
  if (errno == ERANGE) throw bad("too large");
  return v;
}

namespace {

std::string human_bytes(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = 0;
  while (bytes >= 1024 && u < 6) {
    bytes /= 1024;
    ++u;
  }
  return fmt::format("{:.3g} {}", bytes, units[u]);
}

}  // namespace

void check_expected_count(const Volume& volume, const PackOptions& o, double limit, bool allowed) {
  const double n = expected_sphere_count(volume.measure(), o);
  if (n <= limit || allowed) return;
  const double bytes = n * kBytesPerSphere;
  const double ram =
      static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
  throw PackError(fmt::format(
      "{} with radii {} .. {} would take about {:.3g} spheres and {} of memory{}, at about 1 KiB and "
      "20 us of CPU per sphere; that is beyond the {:.3g} spheres basalt-pack packs without asking "
      "(--max-spheres): pass --allow-large to pack it anyway, or give larger radii or a smaller volume",
      volume.description(), o.rmin, o.rmax, n, human_bytes(bytes),
      ram > 0 ? fmt::format(" (this machine has {})", human_bytes(ram)) : std::string(), limit));
}

PreparedPack prepare(const Request& r) {
  PreparedPack p;
  p.pack = r.pack;
  p.assembly = r.assembly;
  p.lattice = r.lattice;
  p.allow_low_fraction = r.allow_low_fraction;
  p.pack.seed = parse_seed(r.seed);
  if (!(r.max_spheres >= 1))
    throw PackError(fmt::format("--max-spheres must be >= 1, got {}", r.max_spheres));
  p.assembly.bonds = !r.no_bonds;
  if (!(p.assembly.bond_tolerance >= 0) || !std::isfinite(p.assembly.bond_tolerance))
    throw PackError(fmt::format("--bond-tolerance must be >= 0, got {}", p.assembly.bond_tolerance));
  if (p.assembly.histogram_bins < 1) throw PackError("--bins must be >= 1");
  if (p.assembly.threads < 1)
    throw PackError(fmt::format("--threads must be >= 1, got {}", p.assembly.threads));
  p.pack.threads = p.assembly.threads;
  check_options(p.pack);
  p.assembly.tags.clear();
  for (const auto& t : r.tag_layers) p.assembly.tags.push_back(parse_tag_layer(t));
  if (!r.output.empty()) check_output(r.output);

  switch (r.shape) {
    case Shape::box: {
      const Vec3 lo = parse_vec3(r.origin, "--origin"), ext = parse_vec3(r.size, "--size");
      p.volume = make_box(lo, {lo[0] + ext[0], lo[1] + ext[1], lo[2] + ext[2]});
      break;
    }
    case Shape::cylinder:
      p.volume = make_cylinder(parse_vec3(r.origin, "--origin"), r.radius, r.height);
      break;
    case Shape::sphere:
      p.volume = make_sphere(parse_vec3(r.centre, "--centre"), r.radius);
      break;
    case Shape::mesh:
      p.volume = load_mesh(r.mesh_file);
      break;
  }
  // Unknown tag faces fail now, not after packing.
  (void)region_tags(*p.volume, {}, {}, p.assembly.tags);
  check_expected_count(*p.volume, p.pack, r.max_spheres, r.allow_large);
  if (r.lattice && p.pack.exponent) throw PackError("--lattice and --exponent exclude each other");
  return p;
}

PackResult run(PreparedPack& p, const std::function<void()>& packed) {
  PackResult out;
  auto packing = p.lattice ? lattice_packing(*p.volume, p.pack) : pack(*p.volume, p.pack);
  if (packed) packed();
  out.geometry = assemble(*p.volume, packing, p.pack, p.assembly, out.stats);
  out.requested = packing.requested;
  out.not_placed = packing.not_placed;
  // The geometry holds the spheres now: free the packing's copy before the caller writes (memory at 8.7 M
  // spheres).
  packing.centre = {};
  packing.radius = {};
  if (p.lattice) return out;
  out.low = low_fraction_report(*p.volume, p.pack, packing, out.stats.solid_fraction);
  if (out.low.far_below && !p.allow_low_fraction)
    throw PackError(out.low.text + "; nothing written (--allow-low-fraction writes it anyway)");
  return out;
}

}  // namespace basalt::packer
