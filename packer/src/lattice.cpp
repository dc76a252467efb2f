// The lattice-with-jitter fill (pack.hpp: lattice_packing).
#include <fmt/format.h>

#include <cmath>

#include "basalt/packer/error.hpp"
#include "basalt/packer/pack.hpp"
#include "basalt/packer/random.hpp"

namespace basalt::packer {

Packing lattice_packing(const Volume& volume, const PackOptions& opt) {
  const double a = 2 * opt.rmax;
  const auto b = volume.bounds();
  long long n[3];
  for (int k = 0; k < 3; ++k) n[k] = static_cast<long long>(std::floor((b.hi[k] - b.lo[k]) / a));
  Packing out;
  Random rng(opt.seed ^ 0x1a771ce5eedULL);
  for (long long z = 0; z < n[2]; ++z)
    for (long long y = 0; y < n[1]; ++y)
      for (long long x = 0; x < n[0]; ++x) {
        const Vec3 cell{b.lo[0] + (double(x) + 0.5) * a, b.lo[1] + (double(y) + 0.5) * a,
                        b.lo[2] + (double(z) + 0.5) * a};
        if (!(volume.signed_distance(cell) >= opt.rmax)) continue;  // the cell's largest sphere fits
        const double r = opt.rmin + (opt.rmax - opt.rmin) * rng.uniform();
        Vec3 c = cell;
        for (int k = 0; k < 3; ++k) c[k] += (opt.rmax - r) * (2 * rng.uniform() - 1);
        out.centre.push_back(c);
        out.radius.push_back(r);
      }
  if (out.radius.empty())
    throw PackError(
        fmt::format("--lattice: no lattice cell of side 2 rmax = {} fits in {}", a, volume.description()));
  return out;
}

}  // namespace basalt::packer
