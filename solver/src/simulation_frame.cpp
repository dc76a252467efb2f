// Writes a compute rank's frame straight into the output buffer (see simulation_frame.hpp).
#include "basalt/solver/output/simulation_frame.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "basalt/solver/parallel/balance.hpp"

namespace basalt::solver {

template <class Real>
SimulationFrame<Real>::SimulationFrame(const Simulation<Real>& sim, std::uint32_t kinds) : sim_(sim) {
  const auto& p = sim.p_;
  const auto& bonds = sim.bonds_;
  auto& h = header_;
  h.kinds = kinds;
  h.step = sim.clock_.step();
  h.time = sim.clock_.time();
  h.source_rank = sim.comm().rank();
  h.particles = p.n_owned;
  // Owned particles now are those of the last rebuild (only a rebuild migrates or reorders them).
  h.with_rebuild = (kinds & io::kFrameCheckpoint) && p.with_exact_rebuild && p.xr.size() == p.n_owned;
  if (h.with_rebuild) {
    h.rebuild_step = sim.schedule_.last_step();
    h.rebuild_pending = sim.schedule_.pending();
  }
  // The cuts in force since the last rebuild: a restart on as many ranks rebuilds this decomposition.
  if ((kinds & io::kFrameCheckpoint) && sim.comm().rank() == 0)
    attributes_["decomposition_cuts"] = cuts_text(sim.dec_->cuts(0), sim.dec_->cuts(1), sim.dec_->cuts(2));
  if ((kinds & io::kFrameCheckpoint) && sim.comm().rank() == 0)
    for (const auto& [key, value] : sim.checkpoint_attributes_) attributes_[key] = value;
  // Inserted particles' ids go on from this counter after a restart (simulation_flow.cpp).
  if ((kinds & io::kFrameCheckpoint) && sim.comm().rank() == 0 && sim.keeps_next_id())
    attributes_["next_particle_id"] = std::to_string(sim.next_particle_id());
  // A frame only for an in-situ picture carries no bonds (pictures draw particles).
  with_bonds_ = (kinds & (io::kFrameCheckpoint | io::kFrameVtk)) != 0;
  std::size_t m = 0;
  if (with_bonds_) {
    m = bonds.n_both_owned + sim.broken_.size();
    for (std::size_t k = bonds.n_both_owned; k < bonds.size(); ++k) m += owns_ghost_bond(k) ? 1 : 0;
  }
  h.bonds = m;
  h.breaks = with_bonds_ ? sim.broken_.size() : 0;  // the broken bonds come last, in broken_'s order
  if (kinds & io::kFrameCheckpoint)
    for (const auto* c : sim.forces_.history_computes())
      if (c->history_bytes() > 0) {
        history_.emplace_back();
        c->history_records(p, history_.back());
        h.contacts += history_.back().size();
        h.contact_width = std::max(h.contact_width, static_cast<std::uint32_t>(history_.back().width));
      }
  // The scene's optional particle fields that frames carry (Particles' array list); checkpoints add the
  // forces and torques, for a restart's first kick (simulation_kick_forces.cpp).
  p.for_each_array([&](const ArrayInfo& a, const auto&) { h.fields += !a.output.empty() && p.enabled(a); });
  // Mixed precision: the float positions in the run's frame, exactly (frame_origin.hpp).
  if (sim.mixed_) h.fields += h.with_rebuild ? 6 : 3;
  const auto& o = sim.origin_;
  const auto absolute = [&o](std::array<double, 3> x) {
    for (std::size_t d = 0; d < 3; ++d) x[d] += o[d];
    return x;
  };
  if (kinds & io::kFrameCheckpoint) kick_forces_ = p.with_rotation ? 6 : 3;
  h.fields += kick_forces_;
  // Walls: global; the force is summed over the ranks (collective), rank 0 carries them.
  // Mesh walls follow the planar ones (so a checkpoint's wall count covers their history ids, -1 -
  // (planar walls + k)): position = where the rotation axis passes, normal = the axis, velocity = the
  // translation's.
  const auto& wd = sim.forces_.walls();
  if (wd.size() + wd.meshes() > 0) {
    std::vector<double> f;
    for (std::size_t w = 0; w < wd.size(); ++w) f.insert(f.end(), wd.force(w).begin(), wd.force(w).end());
    for (std::size_t k = 0; k < wd.meshes(); ++k)
      f.insert(f.end(), wd.mesh_force(k).begin(), wd.mesh_force(k).end());
    if (sim.comm().size() > 1) sim.comm().sum_all(f);
    if (sim.comm().rank() == 0) {
      for (std::size_t w = 0; w < wd.size(); ++w) {
        const auto& s = wd.spec(w);
        const auto& v = wd.velocity(w);  // a servo wall's: that of the next step
        walls_.push_back({s.name,
                          absolute(wd.point(w)),
                          s.normal,
                          {v[0], v[1], v[2]},
                          {f[3 * w], f[3 * w + 1], f[3 * w + 2]},
                          {}});
        if (wd.servo(w)) {
          const auto at = absolute(wd.point_at_rebuild(w));
          walls_.back().motion_state.assign(at.begin(), at.end());
        }
      }
      for (std::size_t k = 0; k < wd.meshes(); ++k) {
        const auto& s = wd.mesh_spec(k);
        const auto v = s.motion.velocity_at(sim.clock_.time());
        const std::size_t at = 3 * (wd.size() + k);
        walls_.push_back({s.name,
                          absolute(wd.mesh_axis_point(k)),
                          s.axis,
                          {v[0], v[1], v[2]},
                          {f[at], f[at + 1], f[at + 2]},
                          {}});
      }
    }
  }
}

template <class Real>
bool SimulationFrame<Real>::owns_ghost_bond(std::size_t k) const {
  // Both ends owned -> this rank; one end a ghost -> the rank owning the lower id.
  const auto& b = sim_.bonds_;
  const auto i = static_cast<std::size_t>(b.ia[k]), j = static_cast<std::size_t>(b.ib[k]);
  return sim_.p_.id[i] < sim_.p_.id[j];
}

template <class Real>
void SimulationFrame<Real>::write(io::FrameWriter& w) const {
  using io::Column;
  const auto& p = sim_.p_;
  const std::size_t n = p.n_owned;
  const auto owned = [n](const auto& v) { return std::span(v.data(), n); };
  w.column(Column::id, owned(p.id));
  w.column(Column::tag, owned(p.tag));
  const auto& o = sim_.origin_;
  const bool mixed = sim_.mixed_;
  if (mixed) {  // absolute coordinates: the frame's origin plus the float offsets
    for (std::size_t i = 0; i < n; ++i) {
      w.set(Column::x, i, o[0] + double(p.x[i]));
      w.set(Column::y, i, o[1] + double(p.y[i]));
      w.set(Column::z, i, o[2] + double(p.z[i]));
    }
  } else {
    w.column(Column::x, owned(p.x));
    w.column(Column::y, owned(p.y));
    w.column(Column::z, owned(p.z));
  }
  w.column(Column::vx, owned(p.vx));
  w.column(Column::vy, owned(p.vy));
  w.column(Column::vz, owned(p.vz));
  w.column(Column::radius, owned(p.radius));
  w.column(Column::mass, owned(p.inv_mass));
  if (header_.with_rebuild && mixed) {
    for (std::size_t i = 0; i < n; ++i) {
      w.set(Column::x_rebuild, i, o[0] + double(p.xr[i]));
      w.set(Column::y_rebuild, i, o[1] + double(p.yr[i]));
      w.set(Column::z_rebuild, i, o[2] + double(p.zr[i]));
    }
  } else if (header_.with_rebuild) {
    w.column(Column::x_rebuild, std::span(p.xr.data(), n));
    w.column(Column::y_rebuild, std::span(p.yr.data(), n));
    w.column(Column::z_rebuild, std::span(p.zr.data(), n));
  }
  // Bonds with both ends owned come first and go as they are; the bond tag carries the solver's
  // interaction group (restart).
  const auto& b = sim_.bonds_;
  const std::size_t both = with_bonds_ ? b.n_both_owned : 0;
  w.column(Column::bond_a, std::span(b.a.data(), both));
  w.column(Column::bond_b, std::span(b.b.data(), both));
  w.column(Column::bond_rest_length, std::span(b.r0.data(), both));
  if (b.grouped)
    w.column(Column::bond_group, std::span(b.group.data(), both));
  else
    w.fill(Column::bond_group, 0, both, 0);
  std::size_t at = both;
  for (std::size_t k = both; with_bonds_ && k < b.size(); ++k) {
    if (!owns_ghost_bond(k)) continue;
    w.set(Column::bond_a, at, b.a[k]);
    w.set(Column::bond_b, at, b.b[k]);
    w.set(Column::bond_rest_length, at, b.r0[k]);
    w.set(Column::bond_group, at, b.group_of(k));
    ++at;
  }
  w.fill(Column::bond_broken, 0, at, 0);
  // Broken bonds: the bond driver records each once across ranks (same lower-id rule). Flag 2: it
  // broke at this very step (a restart from here restores it, docs/formats.md). Where it broke goes
  // with it (pictures of cracks; NaN when a restart from an older checkpoint did not know).
  for (std::size_t k = 0; with_bonds_ && k < sim_.broken_.size(); ++k) {
    const auto& broken = sim_.broken_[k];
    w.set(Column::bond_a, at, broken.a);
    w.set(Column::bond_b, at, broken.b);
    w.set(Column::bond_rest_length, at, broken.rest_length);
    w.set(Column::bond_group, at, broken.group);
    w.set(Column::bond_broken, at,
          std::uint8_t((broken.step == sim_.clock_.step() ? 2 : 1) | (broken.mode << 2)));
    w.set(Column::break_x, k, o[0] + broken.x);
    w.set(Column::break_y, k, o[1] + broken.y);
    w.set(Column::break_z, k, o[2] + broken.z);
    ++at;
  }
  std::size_t c = 0;
  for (std::size_t model = 0; model < history_.size(); ++model) {
    const auto& r = history_[model];
    w.column(Column::contact_a, r.a, c);
    w.column(Column::contact_b, r.b, c);
    w.fill(Column::contact_model, c, r.size(), static_cast<std::int32_t>(model));
    if (r.width == header_.contact_width) {
      w.column(Column::contact_history, r.values, c * header_.contact_width);
    } else {  // a narrower history than the table's (models of several widths): zeros after its own
      std::vector<double> padded(r.size() * header_.contact_width, 0.0);
      for (std::size_t k = 0; k < r.size(); ++k)
        std::copy(r.at(k), r.at(k) + r.width,
                  padded.begin() + static_cast<std::ptrdiff_t>(k * header_.contact_width));
      w.column(Column::contact_history, padded, c * header_.contact_width);
    }
    c += r.size();
  }
  for (const auto& wall : walls_) w.wall(wall);
  p.for_each_array([&](const ArrayInfo& a, const auto& v) {
    if (!a.output.empty() && p.enabled(a)) w.field(a.output, std::span(v.data(), n));
  });
  if (mixed) {
    const std::array<const Real*, 6> exact{p.x.data(),  p.y.data(),  p.z.data(),
                                           p.xr.data(), p.yr.data(), p.zr.data()};
    for (std::size_t k = 0; k < (header_.with_rebuild ? 6u : 3u); ++k)
      w.field(kFramePositionFields[k], std::span(exact[k], n));
  }
  const std::array<const std::vector<Real>*, 6> forces{&p.fx, &p.fy, &p.fz, &p.tx, &p.ty, &p.tz};
  for (std::size_t k = 0; k < kick_forces_; ++k) w.field(kick_force_fields[k], owned(*forces[k]));
  w.attributes(attributes_);
}

template class SimulationFrame<double>;
template class SimulationFrame<float>;

}  // namespace basalt::solver
