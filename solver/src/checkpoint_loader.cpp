// Each compute rank reads a slice of the checkpoint and the ranks route the rows to their owners
// (basalt/solver/parallel/checkpoint_loader.hpp).
#include "basalt/solver/parallel/checkpoint_loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "basalt/io/geometry_rows.hpp"
#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/scene/frame_origin.hpp"

namespace basalt::solver {

namespace {

/// One particle as it travels between ranks (its particle fields travel alongside, in the same order).
struct ParticleRecord {
  std::int64_t id;
  double x, y, z;     // at the checkpoint
  double ax, ay, az;  // at the last rebuild
  double radius, mass, inv_mass, vx, vy, vz;
  std::int32_t tag;
};

/// What the slice holding an id answers: its owner and position (owner -1: no such id).
struct EndRecord {
  double x, y, z;
  std::int32_t owner;
};

/// One bond as it travels, with its state (a broken one's BreakRecord follows it in a second exchange).
struct BondRecord {
  std::int64_t a, b, row;
  double rest;
  std::int32_t tag;
  std::uint8_t flag;
};

/// What a broken bond carries besides: the distance of its ends and where it broke (NaN: not known).
struct BreakRecord {
  double length, x, y, z;
};

/// One contact as it travels (its history alongside, contact_width values).
struct ContactRecord {
  std::int64_t a, b;
  std::int32_t model;
};

double distance(const io::Vec3& a, const io::Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

void CheckpointLoader::fail(const std::string& where, const std::string& what) const {
  throw io::FormatError(file_.path(), where, what);
}

CheckpointLoader::CheckpointLoader(const io::CheckpointFile& file, const Comm& comm)
    : file_(file), comm_(comm) {
  const auto& h = file.header();
  const int r = comm.rank(), p = comm.size();
  const auto [pb, pe] = io::slice_rows(h.particles, r, p);
  const auto [bb, be] = io::slice_rows(h.bonds, r, p);
  const auto [cb, ce] = io::slice_rows(h.contacts, r, p);
  bond_begin_ = bb;
  contact_begin_ = cb;
  slice_.contact_width = h.run.contact_width;
  agreed<InputError>(
      comm,
      [&, pb = pb, pe = pe, bb = bb, be = be, cb = cb, ce = ce] {
        file.read_particles(pb, pe, slice_);
        file.read_bonds(bb, be, slice_);
        if (h.contacts > 0) file.read_contacts(cb, ce, slice_);
      },
      "--restart: ");
  // Break positions: one row per broken bond, in bond order; this slice's start after the broken bonds
  // of the slices before it.
  const auto broken = static_cast<std::int64_t>(std::count_if(
      slice_.bond_broken.begin(), slice_.bond_broken.end(), [](std::uint8_t f) { return f != 0; }));
  const auto counts = comm.all_gather(broken);
  std::int64_t before = 0, total = 0;
  for (int q = 0; q < p; ++q) {
    if (q < r) before += counts[static_cast<std::size_t>(q)];
    total += counts[static_cast<std::size_t>(q)];
  }
  agreed<InputError>(
      comm,
      [&] {
        if (!h.has_break_position) return;
        if (static_cast<std::size_t>(total) != h.break_positions)
          fail("/bonds/break_position",
               io::Checkpoint::break_rows_text(h.break_positions, static_cast<std::size_t>(total)));
        file.read_break_positions(static_cast<std::size_t>(before), static_cast<std::size_t>(before + broken),
                                  slice_);
      },
      "--restart: ");

  // Slices are ranges of ids (the file is sorted by id): each rank's range tells where an id is.
  slices_ = IdSlices(comm, slice_.geometry.id);
  first_ = slices_.first();
  last_ = slices_.last();
  if (const auto d = slices_.disorder()) {  // every rank found it in the same gathered ranges
    const auto row = io::slice_rows(h.particles, d->rank, p).first;
    const auto previous_row = io::slice_rows(h.particles, d->previous_rank, p).second - 1;
    throw InputError(fmt::format(
        "--restart: {}",
        io::FormatError(file.path(), "/particles/id",
                        d->id == d->previous
                            ? fmt::format("duplicate id {} (rows {} and {})", d->previous, previous_row, row)
                            : fmt::format("ids must be sorted ascending: id {} at row {} follows id {}",
                                          d->id, row, d->previous))
            .what()));
  }
}

CheckpointPart CheckpointLoader::local_part(const Decomposition& dec, const std::array<double, 3>& origin) {
  const auto p = static_cast<std::size_t>(comm_.size());
  const auto& h = file_.header();
  const auto& g = slice_.geometry;
  const std::size_t nf = h.particle_fields.size();

  // 1. Particles (and their fields) to their owners; each row's owner is kept to answer step 2.
  CheckpointPart part;
  std::vector<int> owner(g.size());
  {
    std::vector<std::vector<ParticleRecord>> out(p);
    std::vector<std::vector<double>> fields(p);
    const CheckpointFrame frame(slice_, origin);  // where the whole-checkpoint restart puts each particle
    for (std::size_t i = 0; i < g.size(); ++i) {
      const auto& x = g.position[i];
      const auto& at = h.has_position_at_rebuild ? slice_.position_at_rebuild[i] : x;
      const auto in_frame = frame.position(i, h.has_position_at_rebuild);
      owner[i] = dec.rank_of(in_frame[0], in_frame[1], in_frame[2]);
      const auto& v = slice_.velocity[i];
      const double im = h.has_inverse_mass ? slice_.inv_mass[i] : 0.0;
      const auto o = static_cast<std::size_t>(owner[i]);
      out[o].push_back({g.id[i], x[0], x[1], x[2], at[0], at[1], at[2], g.radius[i], g.mass[i], im, v[0],
                        v[1], v[2], g.tag[i]});
      for (const auto& f : slice_.particle_fields) fields[o].push_back(f.second[i]);
    }
    // Of the slice's particles, only ids and positions are asked for from here on.
    slice_.velocity = {};
    slice_.inv_mass = {};
    slice_.position_at_rebuild = {};
    slice_.particle_fields = {};
    slice_.geometry.radius = {};
    slice_.geometry.mass = {};
    slice_.geometry.tag = {};
    const auto owned = comm_.exchange(std::move(out));  // in file (id) order: slices come in rank order
    const auto values = comm_.exchange(std::move(fields));
    auto& c = part.c;
    c = h.run;  // walls, clock, attributes, box, units, contact width
    const std::size_t n = owned.size();
    c.geometry.id.resize(n);
    c.geometry.position.resize(n);
    c.geometry.radius.resize(n);
    c.geometry.tag.resize(n);
    c.geometry.mass.resize(n);
    c.velocity.resize(n);
    c.inv_mass.resize(h.has_inverse_mass ? n : 0);
    c.position_at_rebuild.resize(h.has_position_at_rebuild ? n : 0);
    for (std::size_t f = 0; f < nf; ++f)
      c.particle_fields.emplace_back(h.particle_fields[f], std::vector<double>(n));
    for (std::size_t i = 0; i < n; ++i) {
      const auto& q = owned[i];
      c.geometry.id[i] = q.id;
      c.geometry.position[i] = {q.x, q.y, q.z};
      c.geometry.radius[i] = q.radius;
      c.geometry.tag[i] = q.tag;
      c.geometry.mass[i] = q.mass;
      c.velocity[i] = {q.vx, q.vy, q.vz};
      if (h.has_inverse_mass) c.inv_mass[i] = q.inv_mass;
      if (h.has_position_at_rebuild) c.position_at_rebuild[i] = {q.ax, q.ay, q.az};
      for (std::size_t f = 0; f < nf; ++f) c.particle_fields[f].second[i] = values[i * nf + f];
    }
  }

  // 2. The owners and positions of the bond and contact ends this rank read, from the slices holding them.
  std::optional<std::string> error;
  std::vector<std::int64_t> end_ids;
  const auto& bonds = g.bonds;
  for (std::size_t k = 0; k < bonds.size(); ++k)
    for (const auto id : {bonds[k].a, bonds[k].b}) end_ids.push_back(id);
  for (const auto& ids : slice_.contact_ids) {
    end_ids.push_back(ids[0]);
    if (ids[1] >= 0) end_ids.push_back(ids[1]);
  }
  std::sort(end_ids.begin(), end_ids.end());
  end_ids.erase(std::unique(end_ids.begin(), end_ids.end()), end_ids.end());
  std::vector<std::vector<std::int64_t>> ask(p);
  std::vector<EndRecord> ends(end_ids.size(), EndRecord{0, 0, 0, -1});
  for (std::size_t j = 0; j < end_ids.size(); ++j) {
    const int s = slices_.slice_of(end_ids[j]);
    if (s >= 0) ask[static_cast<std::size_t>(s)].push_back(end_ids[j]);
  }
  std::vector<std::size_t> asked_counts;
  auto asked = comm_.exchange(ask, &asked_counts);
  std::vector<std::vector<EndRecord>> answer(p);
  {
    std::size_t q = 0;
    for (std::size_t r = 0; r < p; ++r)
      for (std::size_t j = 0; j < asked_counts[r]; ++j, ++q) {
        const auto at = std::lower_bound(g.id.begin(), g.id.end(), asked[q]);
        if (at == g.id.end() || *at != asked[q]) {
          answer[r].push_back({0, 0, 0, -1});
        } else {
          const auto i = static_cast<std::size_t>(at - g.id.begin());
          const auto& x = g.position[i];
          answer[r].push_back({x[0], x[1], x[2], owner[i]});
        }
      }
  }
  {
    std::vector<std::int64_t>().swap(asked);
    const auto answers = comm_.exchange(std::move(answer));  // per slice, in the order asked (ascending ids)
    std::size_t q = 0;
    for (std::size_t r = 0; r < p; ++r)
      for (const auto id : ask[r]) {
        const auto j =
            static_cast<std::size_t>(std::lower_bound(end_ids.begin(), end_ids.end(), id) - end_ids.begin());
        ends[j] = answers[q++];
      }
  }
  const auto end_of = [&](std::int64_t id) -> const EndRecord& {
    return ends[static_cast<std::size_t>(std::lower_bound(end_ids.begin(), end_ids.end(), id) -
                                         end_ids.begin())];
  };
  // Each bond end's entry in `ends`, looked up once.
  std::vector<std::uint32_t> bond_end(2 * bonds.size());
  for (std::size_t k = 0; k < bonds.size() && !error; ++k)
    for (int e = 0; e < 2; ++e) {
      const auto id = e == 0 ? bonds[k].a : bonds[k].b;
      const auto j =
          static_cast<std::size_t>(std::lower_bound(end_ids.begin(), end_ids.end(), id) - end_ids.begin());
      bond_end[2 * k + static_cast<std::size_t>(e)] = static_cast<std::uint32_t>(j);
      if (ends[j].owner < 0 && !error)
        error = fmt::format("--restart: {}",
                            io::FormatError(file_.path(), "/bonds/pairs",
                                            fmt::format("bond {} refers to particle id {}, which "
                                                        "does not exist",
                                                        bond_begin_ + k, id))
                                .what());
    }
  for (std::size_t k = 0; k < slice_.contact_ids.size() && !error; ++k) {
    const auto& ids = slice_.contact_ids[k];
    for (int e = 0; e < 2 && !error; ++e)
      if ((e == 0 || ids[1] >= 0) && end_of(ids[static_cast<std::size_t>(e)]).owner < 0)  // -1 - i: wall i
        error = fmt::format("--restart: {}",
                            io::FormatError(file_.path(), "/contacts/ids",
                                            fmt::format("contact {}: particle id {} does not exist",
                                                        contact_begin_ + k, ids[static_cast<std::size_t>(e)]))
                                .what());
  }
  if (auto e = comm_.agree_error(error)) throw InputError(*e);

  // 3. Bonds, with their state, to the owners of both ends.
  {
    std::vector<std::vector<BondRecord>> send(p);
    std::vector<std::vector<BreakRecord>> breaks(p);
    constexpr double unknown = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t k = 0, nb = 0; k < bonds.size(); ++k) {
      const auto& b = bonds[k];
      const auto& ea = ends[bond_end[2 * k]];
      const auto& eb = ends[bond_end[2 * k + 1]];
      const std::uint8_t flag = slice_.bond_broken[k];
      const BondRecord rec{b.a,   b.b, static_cast<std::int64_t>(bond_begin_ + k), slice_.bond_rest_length[k],
                           b.tag, flag};
      const auto oa = static_cast<std::size_t>(ea.owner), ob = static_cast<std::size_t>(eb.owner);
      send[oa].push_back(rec);
      if (ob != oa) send[ob].push_back(rec);
      if (flag == 0) continue;
      BreakRecord br{distance({ea.x, ea.y, ea.z}, {eb.x, eb.y, eb.z}), unknown, unknown, unknown};
      if (h.has_break_position) {
        const auto& w = slice_.bond_break_position[nb];
        br.x = w[0];
        br.y = w[1];
        br.z = w[2];
      }
      ++nb;
      breaks[oa].push_back(br);
      if (ob != oa) breaks[ob].push_back(br);
    }
    slice_.geometry.bonds = {};
    slice_.bond_rest_length = {};
    slice_.bond_broken = {};
    slice_.bond_break_position = {};
    const auto mine = comm_.exchange(std::move(send));           // in file order
    const auto broken_rows = comm_.exchange(std::move(breaks));  // the same order, broken ones only
    // No pair bonded twice: both copies of a pair reach the owner of its first end.
    {
      std::vector<std::pair<std::pair<std::int64_t, std::int64_t>, std::int64_t>> keys;
      keys.reserve(mine.size());
      for (const auto& b : mine) keys.push_back({{b.a, b.b}, b.row});
      std::sort(keys.begin(), keys.end());
      for (std::size_t k = 1; k < keys.size() && !error; ++k)
        if (keys[k].first == keys[k - 1].first)
          error = fmt::format(
              "--restart: {}: /bonds/pairs: bonds {} and {} (counted from 0 in file order) both join "
              "particles {} "
              "and {}: a pair bonded twice acts as two springs; remove one",
              file_.path().string(), keys[k - 1].second, keys[k].second, keys[k].first.first,
              keys[k].first.second);
    }
    if (auto e = comm_.agree_error(error)) throw InputError(*e);
    auto& c = part.c;
    const std::size_t m = mine.size();
    c.geometry.bonds.resize(m);
    c.bond_rest_length.resize(m);
    c.bond_broken.resize(m);
    part.bond_length.assign(m, 0.0);
    for (std::size_t k = 0, nb = 0; k < m; ++k) {
      const auto& b = mine[k];
      c.geometry.bonds[k] = {b.a, b.b, b.tag};
      c.bond_rest_length[k] = b.rest;
      c.bond_broken[k] = b.flag;
      if (b.flag == 0) continue;
      const auto& br = broken_rows[nb++];
      part.bond_length[k] = br.length;
      if (h.has_break_position) c.bond_break_position.push_back({br.x, br.y, br.z});
    }
  }

  // 4. Contact histories to the owners of both particles of the pair.
  if (h.contacts > 0) {
    const std::size_t w = h.run.contact_width;
    std::vector<std::vector<ContactRecord>> send(p);
    std::vector<std::vector<double>> history(p);
    for (std::size_t k = 0; k < slice_.contact_ids.size(); ++k) {
      const auto& ids = slice_.contact_ids[k];
      const int oa = end_of(ids[0]).owner, ob = ids[1] >= 0 ? end_of(ids[1]).owner : oa;
      const ContactRecord rec{ids[0], ids[1], slice_.contact_model[k]};
      const auto* hv = slice_.contact_history.data() + k * w;
      send[static_cast<std::size_t>(oa)].push_back(rec);
      history[static_cast<std::size_t>(oa)].insert(history[static_cast<std::size_t>(oa)].end(), hv, hv + w);
      if (ob != oa) {
        send[static_cast<std::size_t>(ob)].push_back(rec);
        history[static_cast<std::size_t>(ob)].insert(history[static_cast<std::size_t>(ob)].end(), hv, hv + w);
      }
    }
    const auto mine = comm_.exchange(std::move(send));
    auto values = comm_.exchange(std::move(history));
    auto& c = part.c;
    c.contact_ids.resize(mine.size());
    c.contact_model.resize(mine.size());
    for (std::size_t k = 0; k < mine.size(); ++k) {
      c.contact_ids[k] = {mine[k].a, mine[k].b};
      c.contact_model[k] = mine[k].model;
    }
    c.contact_history = std::move(values);
  }
  slice_ = io::Checkpoint{};
  return part;
}

std::vector<io::Vec3> positions_of(const Comm& comm, const std::vector<std::int64_t>& wanted,
                                   const std::vector<std::int64_t>& held_ids,
                                   const std::vector<io::Vec3>& held_positions) {
  // Every rank's wanted ids to every rank (rare: particles a re-balance moved while the restart replayed
  // the last rebuild); the one holding each answers it.
  const auto p = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<std::int64_t>> out(p, wanted);
  std::vector<std::size_t> counts;
  const auto asked = comm.exchange(out, &counts);
  std::vector<std::vector<io::Vec3>> answer(p);
  std::vector<std::vector<std::int64_t>> which(p);
  {
    std::size_t q = 0;
    for (std::size_t r = 0; r < p; ++r)
      for (std::size_t j = 0; j < counts[r]; ++j, ++q) {
        const auto at = std::lower_bound(held_ids.begin(), held_ids.end(), asked[q]);
        if (at == held_ids.end() || *at != asked[q]) continue;
        which[r].push_back(static_cast<std::int64_t>(j));
        answer[r].push_back(held_positions[static_cast<std::size_t>(at - held_ids.begin())]);
      }
  }
  const auto index = comm.exchange(which);
  const auto got = comm.exchange(answer);
  std::vector<io::Vec3> result(wanted.size());
  std::vector<char> found(wanted.size(), 0);
  for (std::size_t k = 0; k < got.size(); ++k) {
    const auto j = static_cast<std::size_t>(index[k]);
    result[j] = got[k];
    found[j] = 1;
  }
  std::optional<std::string> error;
  for (std::size_t j = 0; j < wanted.size() && !error; ++j)
    if (!found[j]) error = fmt::format("restart: particle id {} is on no rank", wanted[j]);
  if (auto e = comm.agree_error(error)) throw InputError(*e);
  return result;
}

}  // namespace basalt::solver
