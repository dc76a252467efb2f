// Per-contact history (the pair driver's History, carried by the pair's ids across rebuilds, migration
// and ranks), checked with the test model test_contact_age, whose force depends on the history (the
// steps a pair has been touching):
// - two spheres colliding while crossing from one rank to the other, with rebuilds forced during the
//   contact: the recorded age equals the number of touching steps the test counts itself, every step;
// - the wave cube with aging contacts and a pulse strong enough to migrate particles: the same
//   kinetic energies (1e-9) and the same contact ages on any number of ranks as in a serial run.
// Restart with history (bit for bit) is io_e2e.restart_history.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

using Age = std::tuple<std::int64_t, std::int64_t, double>;  // lower id, higher id, steps in contact

/// Collective: every contact's age across ranks, sorted, on every rank. A pair between two ranks is
/// listed on both, and each saves its own record of it: the two must agree (then they count once; two
/// different ages for one pair stay two entries, which the tests catch).
std::vector<Age> contact_ages(const Simulation<double>& sim, MPI_Comm comm) {
  std::vector<double> mine;  // (a, b, age) triples as doubles (ids are small)
  for (const auto& c : sim.force_computes()) {
    if (c->history_bytes() == 0) continue;
    ContactRecords r;
    c->history_records(sim.particles(), r);
    for (std::size_t k = 0; k < r.size(); ++k)
      mine.insert(mine.end(),
                  {double(std::min(r.a[k], r.b[k])), double(std::max(r.a[k], r.b[k])), r.at(k)[0]});
  }
  int size = 1;
  MPI_Comm_size(comm, &size);
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  std::vector<Age> ages;
  for (std::size_t k = 0; k + 2 < all.size(); k += 3)
    ages.emplace_back(std::int64_t(all[k]), std::int64_t(all[k + 1]), all[k + 2]);
  std::sort(ages.begin(), ages.end());
  ages.erase(std::unique(ages.begin(), ages.end()), ages.end());
  return ages;
}

/// Collective: the history records of all ranks, each rank's own counted (not merged).
int record_count(const Simulation<double>& sim, MPI_Comm comm) {
  int mine = 0;
  for (const auto& c : sim.force_computes()) {
    ContactRecords r;
    c->history_records(sim.particles(), r);
    mine += static_cast<int>(r.size());
  }
  int all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_SUM, comm);
  return all;
}

/// Collective: the rank owning particle `id`.
int owner(const Simulation<double>& sim, std::int64_t id, MPI_Comm comm) {
  int rank = 0, mine = -1, o = -1;
  MPI_Comm_rank(comm, &rank);
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.id[i] == id) mine = rank;
  MPI_Allreduce(&mine, &o, 1, MPI_INT, MPI_MAX, comm);
  return o;
}

/// Collective: position x and whether particle `id` is owned here (sums over ranks).
double position_x(const Simulation<double>& sim, std::int64_t id, MPI_Comm comm) {
  const auto& p = sim.particles();
  double x = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.id[i] == id) x = p.x[i];
  double sum = 0;
  MPI_Allreduce(&x, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum;
}

}  // namespace

TEST(ContactHistory, AgeCountsTouchingStepsAcrossRebuildsAndRanks) {
  const int n = basalt::test::size();
  if (n > 2) GTEST_SKIP() << "two spheres fill at most two ranks";
  // Two spheres of radius 0.5 drifting along +x, the left one faster: they touch at t = 0.5 and stay
  // in contact for about pi sqrt(m/2 / K) = 1.6 time units, while the left one crosses the ranks'
  // boundary (x = -0.55 on two ranks); a soft K keeps the overlap small.
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 0.01
steps = 0
skin = 0.02
[[interactions]]
type = "test_contact_age"
K = 1.0
growth = 1.0
saturation = 50
)");
  basalt::io::Geometry g;
  g.add_particle(1, {-1.1, 0, 0}, 0.5);
  g.add_particle(2, {0.0, 0, 0}, 0.5);
  const auto opt = basalt::test::quiet({n, 1, 1});
  Simulation<double> sim(scene, g, basalt::test::world(), opt);
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) p.vx[i] = p.id[i] == 1 ? 0.7 : 0.5;
  sim.state_changed();

  double expected = 0;  // steps in contact, counted here from the positions
  int touching_steps = 0, crossed_while_touching = 0, split_steps = 0;
  double last_x1 = position_x(sim, 1, basalt::test::world());
  for (int step = 1; step <= 400; ++step) {
    sim.step();
    if (step % 7 == 0) sim.force_rebuild();  // history must survive any rebuild
    const double x1 = position_x(sim, 1, basalt::test::world()),
                 x2 = position_x(sim, 2, basalt::test::world());
    const bool touching = std::abs(x2 - x1) < 1.0;
    expected = touching ? expected + 1 : 0;
    touching_steps += touching;
    if (touching && n == 2 && (last_x1 < -0.55) != (x1 < -0.55)) ++crossed_while_touching;
    last_x1 = x1;
    const auto ages = contact_ages(sim, basalt::test::world());
    double age = 0;
    for (const auto& [a, b, s] : ages) {
      EXPECT_EQ(a, 1);
      EXPECT_EQ(b, 2);
      age = s;
    }
    EXPECT_LE(ages.size(), 1u) << "step " << step << ": a contact recorded twice";
    // Each rank listing the contact records its own history of it (ForceCompute::history_records): a
    // contact between two ranks' particles twice, one within a rank once.
    if (touching) {
      const int listing =
          owner(sim, 1, basalt::test::world()) != owner(sim, 2, basalt::test::world()) ? 2 : 1;
      EXPECT_EQ(record_count(sim, basalt::test::world()), listing) << "step " << step;
      split_steps += listing == 2;
    }
    ASSERT_EQ(age, expected) << "step " << step;
  }
  EXPECT_GT(touching_steps, 100) << "the spheres must have collided";
  if (n == 2) {
    EXPECT_EQ(crossed_while_touching, 1) << "sphere 1 must change rank during the contact";
    EXPECT_GT(split_steps, 0) << "the contact must have been between two ranks' particles";
  }
  // The contact ended: both move apart, the faster one is now the right one.
  EXPECT_GT(position_x(sim, 2, basalt::test::world()) - position_x(sim, 1, basalt::test::world()), 1.0);
}

TEST(ContactHistory, AgingContactsAreDecompositionInvariant) {
  // The wave cube with aging contacts instead of linear elastic ones and a 5x pulse: contacts form and
  // age while particles migrate (rebuilds with migration from step ~150 at np > 1).
  auto scene = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  const auto with_age = basalt::test::scene_from(R"(
[run]
dt = 1.0e-3
steps = 0
skin = 0.02
[[interactions]]
type = "test_contact_age"
K = 1000.0
growth = 0.5
saturation = 20
)");
  scene.contacts = with_age.contacts;
  scene.skin = 0.02;
  scene.walls[0].motion.amplitude = 0.5;
  const auto g = basalt::test::cube1();
  constexpr int kSteps = 400;
  const auto run = [&](MPI_Comm comm, std::array<int, 3> dims) {
    basalt::test::FieldRun r(scene, g, comm, basalt::test::quiet(dims));
    r.run(kSteps);
    return std::make_tuple(r.sink.column(0), contact_ages(r.sim, comm), r.sim.rebuilds());
  };
  const int n = basalt::test::size();
  std::vector<double> ref_ke(kSteps);
  std::vector<Age> ref_ages;
  if (basalt::test::rank() == 0) {
    auto [ke, ages, rebuilds] = run(MPI_COMM_SELF, {1, 1, 1});
    ref_ke = ke;
    ref_ages = ages;
    double total = 0;
    for (const auto& a : ages) total += std::get<2>(a);
    std::printf("serial: %zu aged contacts at step %d (total age %.0f), %lld rebuilds\n", ages.size(), kSteps,
                total, static_cast<long long>(rebuilds));
    EXPECT_GT(ages.size(), 50u) << "contacts must have formed";
    EXPECT_GT(rebuilds, 5);
  }
  MPI_Bcast(ref_ke.data(), kSteps, MPI_DOUBLE, 0, basalt::test::world());
  if (n == 1) return;
  std::vector<std::array<int, 3>> grids{{1, 1, n}};
  if (n == 4) grids.push_back({1, 2, 2});
  for (const auto& dims : grids) {
    const auto [ke, ages, rebuilds] = run(basalt::test::world(), dims);
    if (basalt::test::rank() != 0) continue;
    const double worst = basalt::test::worst_relative(ke, ref_ke, 1e-9);
    EXPECT_LT(worst, 1e-9) << "dims " << dims[0] << "," << dims[1] << "," << dims[2];
    EXPECT_EQ(ages, ref_ages) << "dims " << dims[0] << "," << dims[1] << "," << dims[2];
    std::printf("np %d dims %d,%d,%d: max relative KE difference %.3g, %zu aged contacts\n", n, dims[0],
                dims[1], dims[2], worst, ages.size());
  }
}

TEST(ContactHistory, PairsGoToTheFirstGroupThatTakesThemAcrossModels) {
  if (basalt::test::rank() != 0) return;
  // Three spheres in a row, tags 0, 0, 1, squeezed together: with two contact models (linear_elastic
  // for tags 0-0, test_contact_age with growth 0, i.e. the same law, for 0-1), each pair goes to the
  // model of the first group that takes it, and the run equals one with linear_elastic for all pairs.
  const std::string common = R"(
[run]
dt = 1e-3
steps = 0
skin = 0.05
)";
  const auto two_models = basalt::test::scene_from(common + R"(
[[interactions]]
type = "linear_elastic"
K = 100.0
tags = [0, 0]
[[interactions]]
type = "test_contact_age"
K = 100.0
growth = 0.0
tags = [0, 1]
)");
  const auto one_model = basalt::test::scene_from(common + R"(
[[interactions]]
type = "linear_elastic"
K = 100.0
)");
  basalt::io::Geometry g;
  g.add_particle(1, {0, 0, 0}, 0.5, 0);
  g.add_particle(2, {1.05, 0, 0}, 0.5, 0);
  g.add_particle(3, {2.1, 0.1, 0}, 0.5, 1);
  const auto opt = basalt::test::quiet();
  Simulation<double> a(two_models, g, MPI_COMM_SELF, opt), b(one_model, g, MPI_COMM_SELF, opt);
  ASSERT_EQ(a.force_computes().size(), 2u);
  for (auto* sim : {&a, &b}) {
    auto& p = sim->particles();
    for (std::size_t i = 0; i < p.n_owned; ++i) p.vx[i] = p.id[i] == 1 ? 0.5 : (p.id[i] == 3 ? -0.5 : 0.0);
    sim->state_changed();
  }
  std::size_t aged = 0;
  for (int s = 0; s < 400; ++s) {
    a.step();
    b.step();
    ContactRecords r;
    a.force_computes()[1]->history_records(a.particles(), r);
    aged = std::max(aged, r.size());
    for (std::size_t k = 0; k < r.size(); ++k)  // only the 0-1 pair (ids 2 and 3) has an age
      EXPECT_EQ(std::min(r.a[k], r.b[k]) * 10 + std::max(r.a[k], r.b[k]), 23) << "step " << s;
  }
  EXPECT_EQ(aged, 1u) << "the 0-1 pair must have touched";
  const auto& pa = a.particles();
  const auto& pb = b.particles();
  for (std::size_t i = 0; i < pa.n_owned; ++i) {
    std::size_t j = 0;
    while (pb.id[j] != pa.id[i]) ++j;
    EXPECT_NEAR(pa.x[i], pb.x[j], 1e-12) << "id " << pa.id[i];
    EXPECT_NEAR(pa.vx[i], pb.vx[j], 1e-12) << "id " << pa.id[i];
  }
}

TEST(ContactRecords, FindPrefersTheRecordInTheListedOrientation) {
  if (basalt::test::rank() != 0) return;
  // A pair between two ranks is saved by each in its own orientation (owned id first), with its own
  // history: each must get its own back (a restart from a checkpoint holding both is then bit for bit).
  ContactRecords r;
  r.width = 1;
  const double a = 1.0, b = -1.0000000000000002, c = 5.0;
  r.push(7, 3, &c);  // another pair
  r.push(1, 2, &a);
  r.push(2, 1, &b);
  const ContactLookup lr(r);
  ASSERT_GE(lr.find(1, 2), 0);
  EXPECT_EQ(r.at(static_cast<std::size_t>(lr.find(1, 2)))[0], a);
  EXPECT_EQ(r.at(static_cast<std::size_t>(lr.find(2, 1)))[0], b);
  EXPECT_EQ(r.at(static_cast<std::size_t>(lr.find(3, 7)))[0], c);  // one orientation: that one
  EXPECT_EQ(lr.find(1, 3), -1);
  // Saved the other way round first: the orientation still decides, not the order.
  ContactRecords s;
  s.width = 1;
  s.push(2, 1, &b);
  s.push(1, 2, &a);
  const ContactLookup ls(s);
  EXPECT_EQ(s.at(static_cast<std::size_t>(ls.find(1, 2)))[0], a);
  EXPECT_EQ(s.at(static_cast<std::size_t>(ls.find(2, 1)))[0], b);
}

TEST(ContactRecords, LookupFindsTheFirstRecordInTheAskedOrientation) {
  if (basalt::test::rank() != 0) return;
  // The hash table the drivers use at a rebuild against a plain scan: every pair asked for, saved in
  // one orientation, both, several times in each (the first wins), or not at all, with ids large and
  // negative enough to collide in a small table, the same record (or -1) each time.
  ContactRecords r;
  r.width = 1;
  std::vector<std::pair<std::int64_t, std::int64_t>> asked;
  for (std::uint64_t k = 0; k < 3000; ++k) {
    const auto u = [&](std::uint64_t s) { return basalt::test::hash_unit(7 * k + s); };
    const std::int64_t ia = std::int64_t(u(0) * 400) - 50, ib = std::int64_t(u(1) * 400) * 1000003 - 7;
    const double v = double(k);
    if (u(2) < 0.7) r.push(ia, ib, &v);
    if (u(3) < 0.3) r.push(ib, ia, &v);
    if (u(4) < 0.1) r.push(ia, ib, &v);  // a second record in one orientation
    asked.emplace_back(ia, ib);
    asked.emplace_back(ib, ia);
    asked.emplace_back(ia, ia);
  }
  // The rule by a plain scan: the first record saved as ia -> ib, else the first saved as ib -> ia.
  const auto first = [&](std::int64_t ia, std::int64_t ib) -> std::int64_t {
    for (std::size_t k = 0; k < r.size(); ++k)
      if (r.a[k] == ia && r.b[k] == ib) return std::int64_t(k);
    for (std::size_t k = 0; k < r.size(); ++k)
      if (r.a[k] == ib && r.b[k] == ia) return std::int64_t(k);
    return -1;
  };
  const ContactLookup lookup(r);
  std::size_t found = 0;
  for (const auto& [ia, ib] : asked) {
    const auto want = first(ia, ib);
    EXPECT_EQ(lookup.find(ia, ib), want) << ia << " " << ib;
    found += want >= 0;
  }
  EXPECT_GT(found, asked.size() / 2);
  EXPECT_EQ(ContactLookup(ContactRecords{}).find(1, 2), -1);
}
