// basalt-run's geometry goes through basalt::io::read_geometry: the same packing as .geo and as .h5
// gives the same run, bit for bit.
#include <gtest/gtest.h>

#include "basalt/solver/simulation.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

TEST(GeometryInput, GeoAndH5GiveTheSameRun) {
  const auto geo = basalt::test::reference_dir() / "cube1.geo";
  const auto h5 = basalt::test::scratch_dir("geometry-input") / "cube1.h5";
  basalt::io::write_geometry(basalt::io::read_geometry(geo), h5);
  auto scene = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  std::vector<std::vector<double>> series;
  for (const auto& file : {geo, h5}) {
    Simulation<double> sim(scene, basalt::io::read_geometry(file), MPI_COMM_SELF);
    EXPECT_EQ(sim.total_particles(), 8948);
    EXPECT_EQ(sim.bond_count(), 30090);
    basalt::test::MemorySink sink(scene);
    sim.run(100, &sink);
    series.push_back(sink.column(0));
  }
  EXPECT_EQ(series[0], series[1]);
}
