// pile_drift: a granular pile held at rest for many steps (docs/stability.md, "A pile held for 1e7 steps";
// issue 46). --side x --side x --layers spheres (radii 0.425 to 0.575, density 1) on a jittered lattice in a
// box (a floor and four side walls), hertz_mindlin pairs and walls (E = 1e5, nu = 0.25, e = 0.5: the
// contacts' own damping as a user sets it, no global damping; mu = 0.5, rotating spheres), gravity 1, dt =
// 1e-3 (about 0.2 of the critical step). The pile settles for --settle steps, then is held --steps steps:
// the kinetic energy (translational + rotational, over N m g r, m and r the means) and the creep (each
// particle's distance from where it was when the hold began, over the mean radius) sampled every --every
// steps. Prints a table row per precision (double, float, mixed; one at a time): the kinetic energy at the
// start and end of the hold, its largest value and its least-squares slope per 1e6 steps, the largest and
// mean creep at the end and the mean creep's slope per 1e6 steps. One rank. Rerun: tools/bench/pile_drift.sh.
#include <fmt/format.h>
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"
#include "held_pile.hpp"

namespace {

using basalt::io::Geometry;
using namespace basalt::solver;
using basalt::bench::pile;
using basalt::bench::pile_scene;

double slope_per_million(const std::vector<double>& t, const std::vector<double>& y) {
  const double n = double(t.size());
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (std::size_t k = 0; k < t.size(); ++k) st += t[k], sy += y[k], stt += t[k] * t[k], sty += t[k] * y[k];
  return (n * sty - st * sy) / (n * stt - st * st) * 1e6;
}

template <class Real>
void run(const std::string& precision, int side, int layers, std::int64_t settle, std::int64_t steps,
         std::int64_t every) {
  const Geometry g = pile(side, layers);
  double m = 0, r = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    r += g.radius[i] / double(g.size());
    m += 4.0 / 3 * std::numbers::pi * std::pow(g.radius[i], 3) / double(g.size());
  }
  const double scale = double(g.size()) * m * 1.0 * r;  // N m g r
  RunOptions opt;
  opt.quiet = true;
  Simulation<Real> sim(parse_scene_text("[geometry]\nfile = \"unused.geo\"\n" + pile_scene(side, precision),
                                        "pile_drift.toml", "."),
                       g, MPI_COMM_SELF, opt);
  const auto start = std::chrono::steady_clock::now();
  sim.run(settle);
  const auto kinetic = [&] { return sim.kinetic_energy() / scale; };  // translational + rotational
  // Where each particle was when the hold began, by id (a rebuild reorders the owned particles).
  const auto& p = sim.particles();
  std::map<std::int64_t, std::array<double, 3>> x0;
  for (std::size_t i = 0; i < p.n_owned; ++i) x0[p.id[i]] = {double(p.x[i]), double(p.y[i]), double(p.z[i])};
  const double ke_settled = kinetic();
  std::vector<double> t, ke, creep;
  double ke_max = ke_settled, creep_max = 0, creep_mean = 0;
  bool finite = true;
  const auto hold = std::chrono::steady_clock::now();
  for (std::int64_t s = 0; s < steps; s += every) {
    sim.run(std::min(every, steps - s));
    std::vector<double> d(p.n_owned, 0.0);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      const auto& a = x0.at(p.id[i]);
      d[i] = std::hypot(double(p.x[i]) - a[0], double(p.y[i]) - a[1], double(p.z[i]) - a[2]) / r;
    }
    creep_max = *std::max_element(d.begin(), d.end());
    creep_mean = 0;
    for (const double v : d) creep_mean += v / double(d.size());
    const double k = kinetic();
    finite = finite && std::isfinite(k) && std::isfinite(creep_mean);
    t.push_back(double(s + every));
    ke.push_back(k);
    creep.push_back(creep_mean);
    ke_max = std::max(ke_max, k);
  }
  const auto end = std::chrono::steady_clock::now();
  fmt::print(
      "| {} | {} | {} | {:.2e} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {} | {:.0f} + "
      "{:.0f} |\n",
      precision, g.size(), settle, ke_settled, steps, ke.back(), ke_max, slope_per_million(t, ke), creep_max,
      creep_mean, slope_per_million(t, creep), finite ? "yes" : "NO",
      std::chrono::duration<double>(hold - start).count(), std::chrono::duration<double>(end - hold).count());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  CLI::App app{"a granular pile held at rest for many steps: kinetic energy and creep (docs/stability.md)"};
  std::string precision = "all";
  std::int64_t steps = 10'000'000, every = 10'000, settle = 300'000;
  int side = 5, layers = 6;
  app.add_option("--steps", steps, "steps held, per precision");
  app.add_option("--settle", settle, "steps to settle first");
  app.add_option("--every", every, "sample every this many steps");
  app.add_option("--side", side, "spheres along x and y");
  app.add_option("--layers", layers, "layers of spheres");
  app.add_option("--precision", precision, "double, float, mixed or all")
      ->check(CLI::IsMember({"double", "float", "mixed", "all"}));
  int code = 0;
  try {
    app.parse(argc, argv);
    fmt::print(
        "| precision | particles | settling steps | KE after settling / (N m g r) | steps held | KE at the "
        "end | "
        "KE largest | KE slope per 1e6 steps | creep at the end, largest / r | mean / r | mean creep slope "
        "per "
        "1e6 steps / r | finite | seconds (settle + hold) |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: |\n");
    for (const char* prec : {"double", "float", "mixed"}) {
      if (precision != "all" && precision != prec) continue;
      if (std::string(prec) == "double")
        run<double>(prec, side, layers, settle, steps, every);
      else
        run<float>(prec, side, layers, settle, steps, every);
    }
  } catch (const CLI::ParseError& e) {
    code = app.exit(e);
  } catch (const std::exception& e) {
    fmt::print(stderr, "pile_drift: error: {}\n", e.what());
    code = 1;
  }
  MPI_Finalize();
  return code;
}
