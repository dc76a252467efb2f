// libFuzzer target: the checkpoint reader (iolayer/src/h5_checkpoint.cpp, schema basalt-checkpoint) on
// arbitrary bytes. read_checkpoint refuses the file with a FormatError, or returns a checkpoint that
// passes Checkpoint::validate, that is_complete_checkpoint also accepts (the restart's search for the
// newest complete checkpoint must not skip a file read_checkpoint reads), and that survives
// write_checkpoint + read_checkpoint unchanged, bit for bit. is_complete_checkpoint itself answers
// without throwing on any input. Anything else (a crash, a sanitizer report, another exception, an
// allocation over libFuzzer's -malloc_limit_mb) is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "h5_fuzz_file.hpp"

namespace {

using basalt::io::Checkpoint;
using basalt::io::FormatError;

void require(bool ok) {
  if (!ok) std::abort();
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same(const Checkpoint& a, const Checkpoint& b) {
  const auto& g = a.geometry;
  const auto& h = b.geometry;
  bool ok = g.id == h.id && same_bits(g.position, h.position) && same_bits(g.radius, h.radius) &&
            g.tag == h.tag && same_bits(g.mass, h.mass) && g.bonds == h.bonds && g.box_min == h.box_min &&
            g.box_max == h.box_max && g.periodic == h.periodic && g.units == h.units &&
            g.attributes == h.attributes && g.statistics.size() == h.statistics.size();
  for (const auto& [name, v] : g.statistics)
    ok = ok && h.statistics.count(name) && same_bits(v, h.statistics.at(name));
  ok = ok && same_bits(a.velocity, b.velocity) && same_bits(a.inv_mass, b.inv_mass) &&
       same_bits(a.position_at_rebuild, b.position_at_rebuild) && a.rebuild_step == b.rebuild_step &&
       a.rebuild_pending == b.rebuild_pending && same_bits(a.bond_rest_length, b.bond_rest_length) &&
       a.bond_broken == b.bond_broken && a.walls.size() == b.walls.size() &&
       a.particle_fields.size() == b.particle_fields.size() && a.contact_ids == b.contact_ids &&
       a.contact_model == b.contact_model && a.contact_width == b.contact_width &&
       same_bits(a.contact_history, b.contact_history) && a.step == b.step &&
       std::memcmp(&a.time, &b.time, sizeof a.time) == 0 && std::memcmp(&a.dt, &b.dt, sizeof a.dt) == 0 &&
       a.scene_text == b.scene_text;
  for (std::size_t k = 0; ok && k < a.walls.size(); ++k) {
    const auto& w = a.walls[k];
    const auto& v = b.walls[k];
    ok = w.name == v.name && w.position == v.position && w.normal == v.normal && w.velocity == v.velocity &&
         w.force == v.force && same_bits(w.motion_state, v.motion_state);
  }
  for (std::size_t k = 0; ok && k < a.particle_fields.size(); ++k)
    ok = a.particle_fields[k].first == b.particle_fields[k].first &&
         same_bits(a.particle_fields[k].second, b.particle_fields[k].second);
  return ok;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto in = basalt::fuzz::h5_scratch("fuzz-checkpoint", "ckpt_000000.h5");
  basalt::fuzz::write_input(in, data, size);

  const bool complete = basalt::io::is_complete_checkpoint(in);
  std::optional<Checkpoint> c;
  try {
    c = basalt::io::read_checkpoint(in);
  } catch (const FormatError&) {
    return 0;
  }
  c->validate(in);
  require(complete);

  const auto out = basalt::fuzz::h5_scratch("fuzz-checkpoint", "out.h5");
  basalt::io::write_checkpoint(*c, out);
  require(same(*c, basalt::io::read_checkpoint(out)));
  return 0;
}
