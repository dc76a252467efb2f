#pragma once
// The start-up basalt-run and the Python package's Simulation (python/src/simulation.cpp) share: the
// simulation built, the run's description for the output (io::RunInfo) completed, and on a failure the
// I/O ranks released before the error is reported, so that both start alike.
#include <functional>
#include <memory>

#include "basalt/io/io_ranks.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::run {

/// Collective over the compute ranks of `layout`: `build(info)` makes the simulation and gives `info` the
/// geometry's box, periodic flags and units; then `info` takes the restart layout, code version, precision,
/// scene text and dt, and `scene.dt` the run's step (run.dt, or run.dt_fraction x the critical step). An
/// error (alike on every compute rank) first releases the I/O ranks, which wait for the run's
/// information, then is thrown as an InputError.
template <class Real>
std::unique_ptr<solver::Simulation<Real>> start_simulation(
    solver::Scene& scene, const io::RankLayout& layout, io::OutputConfig cfg, const io::VtkFrameWriter& vtk,
    io::RunInfo& info, const std::function<std::unique_ptr<solver::Simulation<Real>>(io::RunInfo&)>& build);

}  // namespace basalt::run
