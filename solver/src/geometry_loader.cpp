// Each compute rank reads a slice of the geometry file and the ranks route the rows to their owners
// (basalt/solver/parallel/geometry_loader.hpp).
#include "basalt/solver/parallel/geometry_loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <optional>

#include "basalt/solver/core/errors.hpp"

namespace basalt::solver {

namespace {

/// One particle as it travels between ranks.
struct ParticleRecord {
  std::int64_t id;
  double x, y, z, radius, mass;
  std::int32_t tag;
};

/// One bond as it travels: its ends, tag and row in the file.
struct BondRecord {
  std::int64_t a, b, row;
  std::int32_t tag;
};

ParticleRecord record_of(const io::Geometry& g, std::size_t i) {
  const auto& p = g.position[i];
  return {g.id[i], p[0], p[1], p[2], g.radius[i], g.has_mass() ? g.mass[i] : 0.0, g.tag[i]};
}

}  // namespace

GeometryExtent extent_of(const io::Geometry& g) {
  GeometryExtent e;
  e.lo.fill(std::numeric_limits<double>::infinity());
  e.hi.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (int d = 0; d < 3; ++d) {
      e.lo[d] = std::min(e.lo[d], g.position[i][d] - g.radius[i]);
      e.hi[d] = std::max(e.hi[d], g.position[i][d] + g.radius[i]);
    }
    e.rmax = std::max(e.rmax, g.radius[i]);
  }
  e.n = static_cast<std::int64_t>(g.size());
  if (!g.id.empty()) {
    e.first_id = g.id.front();
    e.last_id = g.id.back();
  }
  return e;
}

GeometryLoader::GeometryLoader(const io::GeometryFile& file, const Comm& comm) : file_(file), comm_(comm) {
  const auto [begin, end] = io::slice_rows(file.header().particles, comm.rank(), comm.size());
  agreed<InputError>(comm, [&, begin = begin, end = end] { file.read_particles(begin, end, slice_); });
  stats_.particle_rows = slice_.size();
  // This rank's slice of the bond rows too, read once here and routed by local_part: the load checks
  // summarise the slices, and a slice without its bonds has no bond tags (a scene's bond_tag was then
  // reported as matching no bond of the file, though the run took every bond with it).
  const auto [bb, be] = io::slice_rows(file.header().bonds, comm.rank(), comm.size());
  agreed<InputError>(comm, [&, bb = bb, be = be] { slice_.bonds = file.read_bonds(bb, be); });
  stats_.bond_rows = slice_.bonds.size();
  const GeometryExtent mine = extent_of(slice_);
  for (int d = 0; d < 3; ++d) {
    extent_.lo[d] = comm.min(mine.lo[d]);
    extent_.hi[d] = comm.max(mine.hi[d]);
  }
  extent_.rmax = comm.max(mine.rmax);
  extent_.n = static_cast<std::int64_t>(file.header().particles);
  // Slices are ranges of ids (the file is sorted by id): each rank's range tells where an id is.
  slices_ = IdSlices(comm, slice_.id);
  extent_.first_id = slices_.first();
  extent_.last_id = slices_.last();
  if (const auto d = slices_.disorder())  // every rank found it in the same gathered ranges
    throw InputError(fmt::format(
        "{}: /particles/id: ids must be sorted ascending and unique: id {} at row {} follows id {}",
        file.path().string(), d->id, io::slice_rows(file.header().particles, d->rank, comm.size()).first,
        d->previous));
}

void GeometryLoader::to_frame(const std::array<double, 3>& o) {
  for (auto& x : slice_.position)
    for (std::size_t d = 0; d < 3; ++d) x[d] -= o[d];
  for (std::size_t d = 0; d < 3; ++d) {
    extent_.lo[d] -= o[d];
    extent_.hi[d] -= o[d];
  }
}

io::Geometry GeometryLoader::local_part(const Decomposition& dec) {
  const auto p = static_cast<std::size_t>(comm_.size());
  const bool has_mass = file_.header().has_mass;
  const std::string file = file_.path().string();

  // 1. Particles to their owners; the owner of each row of this slice is kept to answer step 2.
  std::vector<int> owner(slice_.size());
  std::vector<std::vector<ParticleRecord>> out(p);
  for (std::size_t i = 0; i < slice_.size(); ++i) {
    const auto& x = slice_.position[i];
    owner[i] = dec.rank_of(x[0], x[1], x[2]);
    out[static_cast<std::size_t>(owner[i])].push_back(record_of(slice_, i));
  }
  std::vector<ParticleRecord> owned = comm_.exchange(out);  // in file (id) order: slices come in rank order
  std::vector<std::vector<ParticleRecord>>(p).swap(out);
  stats_.owned = owned.size();

  // 2. Bonds: this rank's slice of bond rows; the slices holding their ends tell the ends' owners.
  const std::size_t bb = io::slice_rows(file_.header().bonds, comm_.rank(), comm_.size()).first;
  std::vector<io::Bond> bonds = std::move(slice_.bonds);  // read by the constructor
  slice_.bonds.clear();
  // Each end id is asked once of the slice holding it; ids sorted, so the answers come back in that order.
  std::vector<std::int64_t> end_ids;
  end_ids.reserve(2 * bonds.size());
  std::optional<std::string> error;
  for (std::size_t k = 0; k < bonds.size(); ++k)
    for (const auto id : {bonds[k].a, bonds[k].b}) {
      if (slices_.slice_of(id) < 0) {
        if (!error)
          error = fmt::format("{}: /bonds/pairs: bond {} refers to particle id {}, which does not exist",
                              file, bb + k, id);
        continue;
      }
      end_ids.push_back(id);
    }
  if (auto e = comm_.agree_error(error)) throw InputError(*e);
  std::sort(end_ids.begin(), end_ids.end());
  end_ids.erase(std::unique(end_ids.begin(), end_ids.end()), end_ids.end());
  end_ids.shrink_to_fit();
  std::vector<std::vector<std::int64_t>> ask(p);
  for (const auto id : end_ids) ask[static_cast<std::size_t>(slices_.slice_of(id))].push_back(id);
  std::vector<std::size_t> asked_counts;
  std::vector<std::int64_t> asked = comm_.exchange(ask, &asked_counts);
  std::vector<std::vector<std::int64_t>>(p).swap(ask);
  std::vector<std::vector<std::int32_t>> answer(p);
  {
    std::size_t q = 0;
    for (std::size_t r = 0; r < p; ++r)
      for (std::size_t j = 0; j < asked_counts[r]; ++j, ++q) {
        const auto at = std::lower_bound(slice_.id.begin(), slice_.id.end(), asked[q]);
        answer[r].push_back(at == slice_.id.end() || *at != asked[q]
                                ? -1
                                : owner[static_cast<std::size_t>(at - slice_.id.begin())]);
      }
  }
  std::vector<std::int64_t>().swap(asked);
  const auto owners = comm_.exchange(answer);  // owners[i]: the owner of end_ids[i]
  std::vector<std::vector<std::int32_t>>(p).swap(answer);
  const auto owner_of = [&](std::int64_t id) {
    return owners[static_cast<std::size_t>(std::lower_bound(end_ids.begin(), end_ids.end(), id) -
                                           end_ids.begin())];
  };
  for (std::size_t k = 0; k < bonds.size() && !error; ++k)
    for (const auto id : {bonds[k].a, bonds[k].b})
      if (owner_of(id) < 0 && !error)
        error = fmt::format("{}: /bonds/pairs: bond {} refers to particle id {}, which does not exist", file,
                            bb + k, id);
  if (auto e = comm_.agree_error(error)) throw InputError(*e);
  std::vector<std::vector<BondRecord>> send(p);
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    const int o[2] = {owner_of(bonds[k].a), owner_of(bonds[k].b)};
    const BondRecord rec{bonds[k].a, bonds[k].b, static_cast<std::int64_t>(bb + k), bonds[k].tag};
    send[static_cast<std::size_t>(o[0])].push_back(rec);
    if (o[1] != o[0]) send[static_cast<std::size_t>(o[1])].push_back(rec);
  }
  std::vector<io::Bond>().swap(bonds);
  std::vector<std::int64_t>().swap(end_ids);
  std::vector<BondRecord> mine = comm_.exchange(send);  // in file order, like the particles
  std::vector<std::vector<BondRecord>>(p).swap(send);
  stats_.bonds = mine.size();

  // No pair bonded twice: both copies of a pair reach the owner of its first end.
  {
    std::vector<std::pair<std::pair<std::int64_t, std::int64_t>, std::int64_t>> keys;
    keys.reserve(mine.size());
    for (const auto& b : mine) keys.push_back({{b.a, b.b}, b.row});
    std::sort(keys.begin(), keys.end());
    for (std::size_t k = 1; k < keys.size() && !error; ++k)
      if (keys[k].first == keys[k - 1].first)
        error = fmt::format(
            "{}: /bonds/pairs: bonds {} and {} (counted from 0 in file order) both join particles {} and {}: "
            "a "
            "pair bonded twice acts as two springs; remove one",
            file, keys[k - 1].second, keys[k].second, keys[k].first.first, keys[k].first.second);
  }
  if (auto e = comm_.agree_error(error)) throw InputError(*e);

  // 3. The far ends of bonds with an owned end, from the slices holding them.
  const auto is_owned = [&](std::int64_t id) {
    const auto at = std::lower_bound(owned.begin(), owned.end(), id,
                                     [](const ParticleRecord& r, std::int64_t v) { return r.id < v; });
    return at != owned.end() && at->id == id;
  };
  std::vector<std::int64_t> far;
  for (const auto& b : mine)
    for (const auto id : {b.a, b.b})
      if (!is_owned(id)) far.push_back(id);
  std::sort(far.begin(), far.end());
  far.erase(std::unique(far.begin(), far.end()), far.end());
  std::vector<std::vector<std::int64_t>> want(p);
  for (const auto id : far) want[static_cast<std::size_t>(slices_.slice_of(id))].push_back(id);
  std::vector<std::int64_t>().swap(far);
  std::vector<std::size_t> wanted_counts;
  const auto wanted = comm_.exchange(want, &wanted_counts);
  {
    std::size_t q = 0;
    for (std::size_t r = 0; r < p; ++r)
      for (std::size_t j = 0; j < wanted_counts[r]; ++j, ++q) {
        const auto at = std::lower_bound(slice_.id.begin(), slice_.id.end(), wanted[q]);
        out[r].push_back(record_of(slice_, static_cast<std::size_t>(at - slice_.id.begin())));
      }
  }
  std::vector<ParticleRecord> ends = comm_.exchange(out);  // ascending ids: asked so, slices in id order
  std::vector<std::vector<ParticleRecord>>(p).swap(out);
  stats_.ghost_ends = ends.size();
  slice_ = io::Geometry{};

  // This rank's part: owned particles and far ends merged by id, bonds in file order.
  io::Geometry g;
  const std::size_t n = owned.size() + ends.size();
  g.id.reserve(n);
  g.position.reserve(n);
  g.radius.reserve(n);
  g.tag.reserve(n);
  if (has_mass) g.mass.reserve(n);
  const auto push = [&](const ParticleRecord& r) {
    g.id.push_back(r.id);
    g.position.push_back({r.x, r.y, r.z});
    g.radius.push_back(r.radius);
    g.tag.push_back(r.tag);
    if (has_mass) g.mass.push_back(r.mass);
  };
  std::size_t i = 0, j = 0;
  while (i < owned.size() || j < ends.size())
    push(j == ends.size() || (i < owned.size() && owned[i].id < ends[j].id) ? owned[i++] : ends[j++]);
  std::vector<ParticleRecord>().swap(owned);
  std::vector<ParticleRecord>().swap(ends);
  g.bonds.reserve(mine.size());
  for (const auto& b : mine) g.bonds.push_back({b.a, b.b, b.tag});
  const auto& h = file_.header();
  g.box_min = h.box_min;
  g.box_max = h.box_max;
  g.periodic = h.periodic;
  g.units = h.units;
  return g;
}

}  // namespace basalt::solver
