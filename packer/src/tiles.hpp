#pragma once
// Split packs (docs/packer.md, "Tiles and threads"): a box is cut into tiles across its two longest
// axes and packed in four rounds by the tiles' colours (the parities of their indices), so that tiles
// packed at the same time never meet, and each tile packs against the finished spheres of its earlier
// neighbours. Every tile's result depends only on the seed and its neighbours' results, never on which
// thread packs it or when: the file is the same for every thread count.
#include <cmath>
#include <cstdint>

#include "basalt/packer/pack.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer::detail {

/// One piece of a pack: the whole volume, or one tile.
struct PartSpec {
  /// kWhole: seeding and filling as the options say. A power-law pack with --fill is split in two
  /// rounds, as one pack is: first the power law's radii in every tile (kPowerLaw), then the voids left
  /// (kFill, no seeding), so that filling one tile does not take the voids its neighbours' radii need.
  enum Stage { kWhole, kPowerLaw, kFill } stage = kWhole;
  std::uint64_t seed = 1;
  /// Only centres within this box are placed (a tile, widened by rmax on every side).
  Bounds centre_range{{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, {HUGE_VAL, HUGE_VAL, HUGE_VAL}};
  /// Spheres placed before (earlier neighbours near the tile): obstacles, not part of the result.
  const Packing* fixed = nullptr;
};

/// Seeds, fills and returns the spheres of one part (packer/src/pack.cpp).
Packing pack_part(const Volume& volume, const PackOptions& options, const PartSpec& part);

struct TileLayout {
  int axis[2] = {0, 1};  ///< the two axes cut into tiles
  int n[2] = {1, 1};     ///< tiles along each
  double width[2] = {0, 0};
  Bounds box;
  int count() const { return n[0] * n[1]; }
};

/// Tiles of options.tile_width (default 10 rmax) across the box's two longest axes; one tile (no split)
/// for volumes other than boxes, for tile_width < 0, and for boxes less than two tiles wide.
TileLayout tile_layout(const Volume& volume, const PackOptions& options);

/// Packs the tiles on options.threads threads and joins them in tile order.
Packing pack_tiles(const Volume& volume, const PackOptions& options, const TileLayout& layout);

}  // namespace basalt::packer::detail
