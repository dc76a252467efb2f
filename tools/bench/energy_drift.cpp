// energy_drift: the long-run energy drift of a closed bonded block (docs/stability.md, "Stability at the
// extremes"; issue 13: 1e7 steps in double and float). The particles of cube1.geo in [0, --size)^3 (bonds
// alone, then bonds and contacts; no walls, no damping) with random velocities of 0.05 mm/ms (with their
// net momentum removed, "at rest", and as drawn, "drifting": the block then moves ~120 mm in 1e7 steps), dt =
// 1e-3 ms (0.17 x critical), run --steps steps; the total energy (kinetic + bond + contact) is sampled every
// --every steps. Prints the least-squares slope of the energy per 1e6 steps (relative to the start), the
// largest relative excursion, and the mean of the last tenth against the first tenth. One rank; precision
// double, float or both. Rerun: tools/bench/energy_drift.sh (the table in docs/stability.md).
#include <fmt/format.h>
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"

namespace {

using basalt::io::Geometry;
using namespace basalt::solver;

/// The same hash as the tests' (tests/support/geometries.hpp): a value in [-1, 1) from an integer.
double hash_unit(std::uint64_t k) {
  k += 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

Geometry block_of(const Geometry& g, double hi) {
  Geometry out;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    if (x[0] < hi && x[1] < hi && x[2] < hi) out.add_particle(g.id[i], x, g.radius[i], g.tag[i]);
  }
  out.sort_by_id();
  for (const auto& b : g.bonds)
    if (out.index_of(b.a) >= 0 && out.index_of(b.b) >= 0) out.bonds.push_back(b);
  return out;
}

const char* kScene = R"([geometry]
file = "unused.geo"
[run]
dt = 1e-3
steps = 0
skin = 0.05
energy_check_every = 0
[[interactions]]
type = "linear_bond"
K = 1000.0
)";
const char* kContacts = R"([[interactions]]
type = "linear_elastic"
K = 1000.0
)";

template <class Real>
void run(const Geometry& block, bool contacts, bool at_rest, std::int64_t steps, std::int64_t every) {
  const auto scene =
      parse_scene_text(std::string(kScene) + (contacts ? kContacts : ""), "energy_drift.toml", ".");
  RunOptions opt;
  opt.quiet = true;
  Simulation<Real> sim(scene, block, MPI_COMM_SELF, opt);
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto id = static_cast<std::uint64_t>(p.id[i]);
    p.vx[i] = Real(0.05 * hash_unit(3 * id));
    p.vy[i] = Real(0.05 * hash_unit(3 * id + 1));
    p.vz[i] = Real(0.05 * hash_unit(3 * id + 2));
  }
  if (at_rest) {  // no net momentum: the block stays where it is (else it drifts ~120 mm in 1e7 steps)
    double m = 0, P[3] = {0, 0, 0};
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      const double mi = 1 / double(p.inv_mass[i]);
      m += mi;
      P[0] += mi * double(p.vx[i]);
      P[1] += mi * double(p.vy[i]);
      P[2] += mi * double(p.vz[i]);
    }
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      p.vx[i] = Real(double(p.vx[i]) - P[0] / m);
      p.vy[i] = Real(double(p.vy[i]) - P[1] / m);
      p.vz[i] = Real(double(p.vz[i]) - P[2] / m);
    }
  }
  sim.state_changed();
  auto total = [&] {
    const auto e = sim.energies();
    return e[0] + e[1] + e[2] + e[3];
  };
  const double e0 = total();
  std::vector<double> t, e;
  double worst = 0;
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t s = 0; s < steps; s += every) {
    sim.run(std::min(every, steps - s));
    const double v = total();
    t.push_back(double(sim.current_step()));
    e.push_back(v);
    worst = std::max(worst, std::abs(v - e0) / e0);
    if (std::getenv("ENERGY_DRIFT_SERIES"))
      fmt::print(stderr, "{} {:.6g} {:.6g} {:.6g}\n", sim.current_step(), v / e0, sim.energies()[0] / e0,
                 sim.energies()[1] / e0);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Least-squares slope of e(t).
  const double n = double(t.size());
  double st = 0, se = 0, stt = 0, ste = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    st += t[k];
    se += e[k];
    stt += t[k] * t[k];
    ste += t[k] * e[k];
  }
  const double slope = (n * ste - st * se) / (n * stt - st * st);
  const std::size_t tenth = std::max<std::size_t>(1, t.size() / 10);
  double first = 0, last = 0;
  for (std::size_t k = 0; k < tenth; ++k) {
    first += e[k] / double(tenth);
    last += e[e.size() - 1 - k] / double(tenth);
  }
  double xmax = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    xmax = std::max({xmax, std::abs(double(p.x[i])), std::abs(double(p.y[i])), std::abs(double(p.z[i]))});
  fmt::print("| {} | {} | {} | {} | {} | {:.3g} | {:.2e} | {:.2e} | {:.2e} | {:.3g} | {:.0f} |\n",
             sizeof(Real) == 8 ? "double" : "float", contacts ? "bonds + contacts" : "bonds",
             at_rest ? "at rest" : "drifting", block.size(), steps, e0, slope * 1e6 / e0, worst,
             (last - first) / e0, xmax, seconds);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  CLI::App app{"energy drift of a closed bonded block over many steps (docs/stability.md)"};
  std::string geometry, precision = "both";
  std::int64_t steps = 10'000'000, every = 10'000;
  double size = 2.5;
  app.add_option("--geometry", geometry, "cube1.geo")->required();
  app.add_option("--steps", steps, "steps per precision");
  app.add_option("--every", every, "sample the energy every this many steps");
  app.add_option("--size", size, "the block: particles with every coordinate below this");
  app.add_option("--precision", precision, "double, float or both")
      ->check(CLI::IsMember({"double", "float", "both"}));
  int code = 0;
  try {
    app.parse(argc, argv);
    const auto block = block_of(basalt::io::read_geometry(geometry), size);
    fmt::print(
        "| precision | interactions | momentum | particles | steps | E0 | drift per 1e6 steps (slope, "
        "relative) "
        "| max relative excursion | last tenth - first tenth (relative) | max abs coordinate at the end | "
        "seconds "
        "|\n| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for (const bool contacts : {false, true}) {
      for (const bool at_rest : {true, false}) {
        if (precision != "float") run<double>(block, contacts, at_rest, steps, every);
        if (precision != "double") run<float>(block, contacts, at_rest, steps, every);
      }
    }
  } catch (const CLI::ParseError& e) {
    code = app.exit(e);
  } catch (const std::exception& e) {
    fmt::print(stderr, "energy_drift: error: {}\n", e.what());
    code = 1;
  }
  MPI_Finalize();
  return code;
}
