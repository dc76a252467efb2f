// The Verlet lists against a brute-force N^2 search over all particles of all ranks, at start and
// after particles have moved far enough to migrate between ranks (and leave the initial box); plus
// the halo property: every ghost is owned by another rank and lies within the ghost width.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
using Pair = std::pair<std::int64_t, std::int64_t>;

namespace {

struct All {
  std::vector<std::int64_t> id;
  std::vector<double> x, y, z, r;
};

/// Every rank's owned particles, on every rank.
All gather_owned(const Particles<double>& p) {
  const int n = static_cast<int>(p.n_owned);
  int size = 0;
  MPI_Comm_size(basalt::test::world(), &size);
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, basalt::test::world());
  int total = 0;
  for (int k = 0; k < size; ++k) {
    displs[static_cast<std::size_t>(k)] = total;
    total += counts[static_cast<std::size_t>(k)];
  }
  All a;
  a.id.resize(static_cast<std::size_t>(total));
  MPI_Allgatherv(p.id.data(), n, MPI_INT64_T, a.id.data(), counts.data(), displs.data(), MPI_INT64_T,
                 basalt::test::world());
  for (auto [src, dst] : {std::pair{&p.x, &a.x}, {&p.y, &a.y}, {&p.z, &a.z}, {&p.radius, &a.r}}) {
    dst->resize(static_cast<std::size_t>(total));
    MPI_Allgatherv(src->data(), n, MPI_DOUBLE, dst->data(), counts.data(), displs.data(), MPI_DOUBLE,
                   basalt::test::world());
  }
  return a;
}

/// Pairs (smaller id first) listed anywhere, gathered on every rank; counts duplicates of owned pairs.
std::vector<Pair> gather_pairs(const std::vector<Pair>& mine) {
  std::vector<std::int64_t> flat;
  for (auto [a, b] : mine) {
    flat.push_back(a);
    flat.push_back(b);
  }
  int size = 0;
  MPI_Comm_size(basalt::test::world(), &size);
  const int n = static_cast<int>(flat.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, basalt::test::world());
  int total = 0;
  for (int k = 0; k < size; ++k) {
    displs[static_cast<std::size_t>(k)] = total;
    total += counts[static_cast<std::size_t>(k)];
  }
  std::vector<std::int64_t> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(flat.data(), n, MPI_INT64_T, all.data(), counts.data(), displs.data(), MPI_INT64_T,
                 basalt::test::world());
  std::vector<Pair> out;
  for (std::size_t k = 0; k + 1 < all.size(); k += 2) out.emplace_back(all[k], all[k + 1]);
  return out;
}

void check_lists(const Simulation<double>& sim, const std::set<Pair>& bonded, const std::string& when) {
  const auto& p = sim.particles();
  const double skin = 0.1;
  const All a = gather_owned(p);
  // Every particle owned exactly once.
  std::vector<std::int64_t> ids = a.id;
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end()) << when << ": a particle owned twice";
  EXPECT_EQ(static_cast<std::int64_t>(ids.size()), sim.total_particles()) << when << ": particles lost";

  // Brute force over everything.
  std::set<Pair> expected;
  for (std::size_t i = 0; i < a.id.size(); ++i)
    for (std::size_t j = i + 1; j < a.id.size(); ++j) {
      const double dx = a.x[i] - a.x[j], dy = a.y[i] - a.y[j], dz = a.z[i] - a.z[j];
      const double cut = a.r[i] + a.r[j] + skin;
      if (dx * dx + dy * dy + dz * dz >= cut * cut) continue;
      const Pair pr{std::min(a.id[i], a.id[j]), std::max(a.id[i], a.id[j])};
      if (!bonded.count(pr)) expected.insert(pr);
    }

  // What the lists hold: owned pairs once globally; ghost pairs on both ranks.
  std::vector<Pair> own, ghost;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    for (auto k = sim.own_pairs().offset[i]; k < sim.own_pairs().offset[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(sim.own_pairs().neigh[k]);
      EXPECT_LT(j, p.n_owned);
      own.emplace_back(std::min(p.id[i], p.id[j]), std::max(p.id[i], p.id[j]));
    }
    for (auto k = sim.ghost_pairs().offset[i]; k < sim.ghost_pairs().offset[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(sim.ghost_pairs().neigh[k]);
      EXPECT_GE(j, p.n_owned);
      ghost.emplace_back(std::min(p.id[i], p.id[j]), std::max(p.id[i], p.id[j]));
    }
  }
  const auto all_own = gather_pairs(own), all_ghost = gather_pairs(ghost);
  std::set<Pair> listed(all_own.begin(), all_own.end());
  EXPECT_EQ(listed.size(), all_own.size()) << when << ": an owned pair listed twice";
  std::multiset<Pair> ghost_count(all_ghost.begin(), all_ghost.end());
  for (const auto& pr : std::set<Pair>(all_ghost.begin(), all_ghost.end())) {
    EXPECT_EQ(ghost_count.count(pr), 2u)
        << when << ": ghost pair " << pr.first << "-" << pr.second << " not listed by both ranks";
    EXPECT_FALSE(listed.count(pr)) << when << ": pair listed as owned and as ghost";
    listed.insert(pr);
  }
  EXPECT_EQ(listed.size(), expected.size()) << when;
  std::vector<Pair> missing, extra;
  std::set_difference(expected.begin(), expected.end(), listed.begin(), listed.end(),
                      std::back_inserter(missing));
  std::set_difference(listed.begin(), listed.end(), expected.begin(), expected.end(),
                      std::back_inserter(extra));
  EXPECT_TRUE(missing.empty()) << when << ": " << missing.size() << " pairs missing, first "
                               << missing[0].first << "-" << missing[0].second;
  EXPECT_TRUE(extra.empty()) << when << ": " << extra.size() << " pairs too many";

  // Halo property: ghosts are owned elsewhere and lie within the ghost width of this rank's region.
  std::set<std::int64_t> mine(p.id.begin(), p.id.begin() + static_cast<std::ptrdiff_t>(p.n_owned));
  const auto& dec = sim.decomposition();
  const double w = sim.ghost_width();
  for (std::size_t g = p.n_owned; g < p.size(); ++g) {
    EXPECT_FALSE(mine.count(p.id[g])) << "ghost " << p.id[g] << " is also owned here";
    const double c[3] = {p.x[g], p.y[g], p.z[g]};
    for (int d = 0; d < 3; ++d) {
      EXPECT_GE(c[d], dec.lo(d) - w) << "ghost " << p.id[g];
      EXPECT_LT(c[d], dec.hi(d) + w) << "ghost " << p.id[g];
    }
  }
}

const char* kScene = R"(
[run]
dt = 1e-3
steps = 0
skin = 0.1
energy_check_every = 0
[[interactions]]
type = "linear_elastic"
K = 1000.0
)";

}  // namespace

TEST(Neighbors, BondedCubeMatchesBruteForce) {
  const auto g = basalt::test::cube1();
  const auto scene = basalt::test::scene_from(std::string(kScene) +
                                              "[[interactions]]\ntype = \"linear_bond\"\nK = 1000.0\n");
  Simulation<double> sim(scene, g, basalt::test::world());
  std::set<Pair> bonded;
  for (const auto& b : g.bonds) bonded.insert({std::min(b.a, b.b), std::max(b.a, b.b)});
  check_lists(sim, bonded, "at start");
}

TEST(Neighbors, AfterMigrationMatchesBruteForce) {
  // Unbonded particles flying apart (an expanding cloud): they cross rank boundaries and the box.
  const auto g = basalt::test::sub_cube(basalt::test::cube1(), 0.0, 9.0);
  Simulation<double> sim(basalt::test::scene_from(kScene), g, basalt::test::world());
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto id = static_cast<std::uint64_t>(p.id[i]);
    p.vx[i] = (p.x[i] - 4.5) * 1.0 + 0.5 * basalt::test::hash_unit(3 * id);
    p.vy[i] = (p.y[i] - 4.5) * 1.0 + 0.5 * basalt::test::hash_unit(3 * id + 1);
    p.vz[i] = (p.z[i] - 4.5) * 1.0 + 0.5 * basalt::test::hash_unit(3 * id + 2);
  }
  sim.state_changed();
  check_lists(sim, {}, "at start");
  const auto before = sim.rebuilds();
  sim.run(400);
  EXPECT_GT(sim.rebuilds(), before + 3) << "the test must exercise rebuilds";
  sim.force_rebuild();
  check_lists(sim, {}, "after 400 steps");
  // The cloud left the initial box: open boundaries kept every particle.
  double xmax = -1e9;
  for (std::size_t i = 0; i < p.n_owned; ++i) xmax = std::max(xmax, p.x[i]);
  double global = 0;
  MPI_Allreduce(&xmax, &global, 1, MPI_DOUBLE, MPI_MAX, basalt::test::world());
  EXPECT_GT(global, 9.5);
}
