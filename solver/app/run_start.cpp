#include "run_start.hpp"

#include <optional>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/version.hpp"
#include "restart_support.hpp"

namespace basalt::run {

template <class Real>
std::unique_ptr<solver::Simulation<Real>> start_simulation(
    solver::Scene& scene, const io::RankLayout& layout, io::OutputConfig cfg, const io::VtkFrameWriter& vtk,
    io::RunInfo& info, const std::function<std::unique_ptr<solver::Simulation<Real>>(io::RunInfo&)>& build) {
  std::unique_ptr<solver::Simulation<Real>> sim;
  std::optional<std::string> error;
  try {
    sim = build(info);
    info.attributes = restart_attributes(sim->restart_layout());
    info.attributes["code_version"] = std::string(basalt::kVersion);
    info.attributes["precision"] = scene.precision;  // a restart in the other precision is refused
    info.scene_text = scene.text;
    // run.dt, or run.dt_fraction x the critical step (a staged restart runs a stage's dt: the run's first
    // stays)
    if (scene.clock_base.dt == 0) scene.dt = sim->dt();
    info.dt = scene.dt;  // constant for the run: sent once to the I/O ranks, stored in every checkpoint
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (error) {
    // Release the I/O ranks (they wait for the run's information), then report.
    cfg.checkpoint_every = cfg.frames_every = cfg.fields_every = 0;
    io::OutputClient client(layout, cfg, info, vtk);
    client.finish();
    throw solver::InputError(*error);
  }
  return sim;
}

#define BASALT_INSTANTIATE(R)                                                                           \
  template std::unique_ptr<solver::Simulation<R>> start_simulation<R>(                                  \
      solver::Scene&, const io::RankLayout&, io::OutputConfig, const io::VtkFrameWriter&, io::RunInfo&, \
      const std::function<std::unique_ptr<solver::Simulation<R>>(io::RunInfo&)>&);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::run
