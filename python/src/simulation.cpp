// basalt._core.Simulation: a run driven from Python (docs/python.md). The same start-up and output as
// basalt-run (sliced geometry reading, dedicated I/O ranks or synchronous writing, checkpoints, field
// series), with the run loop's hooks (Simulation::run, StepHook) calling Python, numpy views of the rank's
// particle arrays and the steering calls of Simulation. basalt/simulation.py wraps it.
//
// SPMD: every MPI rank runs the same script. With io_ranks > 0 the last ranks of the world are I/O ranks:
// their constructor serves the compute ranks' output until close() on the compute ranks, then returns an
// object whose is_io_rank is True and whose run() does nothing.
#include "basalt/solver/simulation.hpp"

#include <fmt/format.h>
#include <mpi.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "basalt/io/io_ranks.hpp"
#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/stop_request.hpp"
#include "basalt/solver/models/registry.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/stages.hpp"
#include "bindings.hpp"
#include "client_sink.hpp"
#include "esys_watch.hpp"
#include "geometry_input.hpp"
#include "output_folder.hpp"
#include "process_setup.hpp"
#include "run_start.hpp"
#if BASALT_WITH_VTK
#include "basalt/io/vtk_frame_writer.hpp"
#endif

namespace basalt::python {

namespace py = pybind11;
namespace fs = std::filesystem;
using solver::InputError;
using solver::RunError;
using solver::Scene;

namespace {

class PySimulation;
/// The simulations not closed yet: closed (collectively, in creation order) at exit, before MPI_Finalize.
std::vector<PySimulation*>& live_simulations() {
  static std::vector<PySimulation*> live;
  return live;
}
void close_live_simulations();

/// MPI for the whole interpreter: initialised at the first Simulation (FUNNELED, as basalt-run), finalised at
/// exit (atexit) after closing the simulations still open, unless someone else (mpi4py) initialised it.
void ensure_mpi() {
  int up = 0;
  MPI_Initialized(&up);
  if (up) return;
  basalt::run::bound_heap_growth();  // as basalt-run does (solver/app/process_setup.hpp)
  basalt::run::prefer_eager_shared_memory_messages();
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  py::module_::import("atexit").attr("register")(py::cpp_function([] {
    close_live_simulations();
    int done = 0;
    MPI_Finalized(&done);
    if (!done) MPI_Finalize();
  }));
}

bool mpi_finalized() {
  int done = 0;
  MPI_Finalized(&done);
  return done != 0;
}

/// The start-up's choices, as the Python constructor takes them.
struct Options {
  std::string scene;  ///< a file, or TOML text when `text`
  bool text = false;
  std::string geometry, output, precision;
  int io_ranks = 0;
  std::int64_t checkpoint_every = -1;
  bool quiet = true;
  bool force_dt = false;
};

/// One compute rank's run of precision Real with its output client.
class Run {
 public:
  virtual ~Run() = default;
  virtual std::int64_t run(std::int64_t steps, const std::vector<solver::StepHook>& hooks) = 0;
  virtual py::list run_stages() = 0;
  virtual py::dict state() = 0;
  virtual py::array array(const std::string& name, py::handle owner) = 0;
  virtual py::object gather(const std::vector<std::string>& names, py::handle owner, bool everywhere,
                            bool table) = 0;
  virtual const solver::Comm& comm() const = 0;
  virtual std::int64_t step() const = 0;
  virtual double time() const = 0;
  virtual double dt() const = 0;
  virtual std::int64_t total_particles() const = 0;
  virtual std::size_t owned() const = 0;
  virtual double kinetic_energy() = 0;
  virtual py::dict energies() = 0;
  virtual py::dict walls() = 0;
  virtual void set_dt(double dt) = 0;
  virtual void set_fixed_tags(std::vector<std::int64_t> tags) = 0;
  virtual void set_wall_velocity(const std::string& name, const std::array<double, 3>& v) = 0;
  virtual void move_wall_by(const std::string& name, const std::array<double, 3>& u) = 0;
  virtual void remove_wall(const std::string& name) = 0;
  virtual void add_wall(const std::string& name) = 0;
  virtual void set_wall_motion(const std::string& name, const std::string& keys) = 0;
  virtual void set_body_force(const std::string& name, const std::string& keys) = 0;
  virtual py::list body_forces() const = 0;
  virtual void set_contact(const std::string& name, const std::string& keys) = 0;
  virtual py::list contacts() const = 0;
  virtual void state_changed(bool advance_history) = 0;
  /// Particles in and out now (keys: the TOML of an [[insert]] / [[delete]] table); how many.
  virtual std::int64_t insert(const std::string& keys) = 0;
  virtual std::int64_t remove(const std::string& keys) = 0;
  /// Collective: bonds now, bonds broken so far (every rank's), particles inserted and removed so far.
  virtual std::int64_t bond_count() = 0;
  virtual std::int64_t broken_bonds() = 0;
  /// Collective: the bonds broken so far, every rank's, on every rank: rows (id, id, step it broke at), the
  /// smaller id first, sorted.
  virtual py::array broken_bond_pairs() = 0;
  /// Collective: the value fields.csv's column `name` got at this step (the scene's [[output.fields]] saver,
  /// summed over the compute ranks), None when that saver was not due at this step; KeyError for no such
  /// column.
  virtual py::object saved_field(const std::string& name) = 0;
  virtual std::array<std::int64_t, 2> flow_totals() const = 0;
  /// Collective: a checkpoint of the current step now.
  virtual void checkpoint() = 0;
  /// The critical time step the run estimated at its start (docs/stability.md).
  virtual double critical_dt() const = 0;
  /// Collective: ESyS's neighbour-list rule and spatial domain checked after every step of every run from
  /// now on (esys_watch.hpp; the ESyS front end), the references taken now; again after deletions.
  virtual void esys_watch(double limit2, const std::array<double, 3>& lo,
                          const std::array<double, 3>& hi) = 0;
  virtual void esys_watch_reset() = 0;
  /// Collective: the particles outside the watched domain removed in one rebuild (as ESyS removes them at its
  /// neighbour-list rebuild), the references taken again; how many.
  virtual std::int64_t esys_watch_leave() = 0;
  /// The positions at ESyS's last neighbour-list rebuild: (ids, (n, 3) positions) in id order.
  virtual py::tuple esys_watch_reference() const = 0;
  /// Whether the last step's positions make ESyS rebuild its lists as the next step begins.
  virtual bool esys_watch_rebuild_due() const = 0;
  /// What the time step risks now, one sentence each (Simulation::step_warnings).
  virtual std::vector<std::string> step_warnings() const = 0;
  virtual std::string close() = 0;
};

/// The table of TOML `keys` read by `parse` as the scene's `label` table would be (its messages name
/// "Simulation.<label>").
template <class Parse>
auto parse_keys(const std::string& keys, const std::string& label, Parse parse) {
  toml::table table;
  const std::string source = "Simulation." + label;
  try {
    table = toml::parse(keys, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: {}", source, e.description()));
  }
  solver::TableReader t(table, source, label);
  return parse(t);
}

template <class Real>
class RunOf final : public Run {
 public:
  RunOf(Scene scene, const io::RankLayout& layout, io::OutputConfig cfg, const io::VtkFrameWriter& vtk,
        const Options& o)
      : scene_(std::move(scene)), comm_(layout.compute) {
    solver::RunOptions ro;
    ro.quiet = o.quiet;
    ro.force_dt = o.force_dt;
    io::RunInfo info;
    sim_ = basalt::run::start_simulation<Real>(scene_, layout, cfg, vtk, info, [&](io::RunInfo& run_info) {
      const auto rows = basalt::run::open_geometry(scene_, cfg.dir, comm_, o.quiet, run_info);
      return std::make_unique<solver::Simulation<Real>>(scene_, *rows, layout.compute, ro);
    });
    client_ = std::make_unique<io::OutputClient>(layout, cfg, info, vtk);
    sink_ = std::make_unique<basalt::run::ClientSink>(*client_, cfg.continue_on_error);
  }

  std::int64_t run(std::int64_t steps, const std::vector<solver::StepHook>& hooks) override {
    if (!watch_) return sim_->run(steps, *sink_, hooks);
    std::vector<solver::StepHook> all = hooks;
    all.push_back({1, [this](std::int64_t) { return watch_->check(sim_->particles(), comm_); }, false});
    return sim_->run(steps, *sink_, all);
  }
  void esys_watch(double limit2, const std::array<double, 3>& lo, const std::array<double, 3>& hi) override {
    watch_.emplace(limit2, lo, hi);
    watch_->reset(sim_->particles(), comm_);
  }
  void esys_watch_reset() override {
    if (!watch_) throw RunError("esys_watch_reset before esys_watch");
    watch_->reset(sim_->particles(), comm_);
  }
  std::int64_t esys_watch_leave() override {
    if (!watch_) throw RunError("esys_watch_leave before esys_watch");
    std::vector<solver::DeleteSpec> specs;
    for (const auto& box : watch_->outside_boxes(sim_->particles(), comm_)) {
      solver::DeleteSpec spec;
      spec.name = "esys_domain";
      spec.region.lo = box[0];
      spec.region.hi = box[1];
      specs.push_back(std::move(spec));
    }
    if (specs.empty()) return 0;  // (the rebuild stays pending: taken at the next check)
    const std::int64_t removed = sim_->remove_particles(std::move(specs));
    watch_->reset(sim_->particles(), comm_);
    return removed;
  }
  bool esys_watch_rebuild_due() const override { return watch_ && watch_->rebuild_due(); }
  py::tuple esys_watch_reference() const override {
    if (!watch_) throw RunError("esys_watch_reference before esys_watch");
    const auto& ids = watch_->ids();
    const auto n = static_cast<py::ssize_t>(ids.size());
    py::array_t<std::int64_t> out_ids(n);
    std::copy(ids.begin(), ids.end(), out_ids.mutable_data());
    py::array_t<double> out({n, py::ssize_t(3)});
    std::copy(watch_->reference().begin(), watch_->reference().end(), out.mutable_data());
    return py::make_tuple(out_ids, out);
  }
  py::list run_stages() override {
    py::list out;
    solver::run_stages(*sim_, *sink_, scene_.stages,
                       [&](const solver::StageSpec& st, const solver::StageReport& r) {
                         py::dict d;
                         d["name"] = r.name;
                         d["first_step"] = r.first_step;
                         d["steps"] = r.steps;
                         d["condition_met"] = r.condition_met;
                         d["value"] = r.value;
                         d["line"] = solver::describe(st, r);
                         out.append(d);
                       });
    return out;
  }
  const solver::Comm& comm() const override { return comm_; }
  std::int64_t step() const override { return sim_->current_step(); }
  double time() const override { return sim_->time(); }
  double dt() const override { return sim_->dt(); }
  std::int64_t total_particles() const override { return sim_->total_particles(); }
  std::size_t owned() const override { return sim_->particles().n_owned; }
  double kinetic_energy() override { return sim_->kinetic_energy(); }
  void set_dt(double dt) override { sim_->set_dt(dt); }
  void set_fixed_tags(std::vector<std::int64_t> tags) override { sim_->set_fixed_tags(std::move(tags)); }
  void set_wall_velocity(const std::string& name, const std::array<double, 3>& v) override {
    sim_->set_wall_velocity(name, v);
  }
  void move_wall_by(const std::string& name, const std::array<double, 3>& u) override {
    sim_->move_wall_by(name, u);
  }
  void remove_wall(const std::string& name) override { sim_->remove_wall(name); }
  void add_wall(const std::string& name) override { sim_->add_wall(name); }
  void set_wall_motion(const std::string& name, const std::string& keys) override {
    sim_->set_wall_motion(name, keys);
  }
  void set_body_force(const std::string& name, const std::string& keys) override {
    sim_->set_body_force(name, keys);
  }
  void set_contact(const std::string& name, const std::string& keys) override {
    sim_->set_contact(name, keys);
  }
  py::list contacts() const override {
    py::list l;
    for (const auto& g : scene_.contacts) l.append(py::make_tuple(g.name, g.model));
    return l;
  }
  py::list body_forces() const override {
    py::list l;
    for (const auto& b : scene_.body_forces) l.append(py::make_tuple(b.name, b.model));
    return l;
  }
  void state_changed(bool advance_history) override { sim_->state_changed(advance_history); }
  std::int64_t insert(const std::string& keys) override {
    return sim_->insert_particles(parse_keys(
        keys, "insert", [&](solver::TableReader& t) { return solver::parse_insert(t, scene_.density); }));
  }
  std::int64_t remove(const std::string& keys) override {
    return sim_->remove_particles(
        parse_keys(keys, "delete", [](solver::TableReader& t) { return solver::parse_delete(t); }));
  }
  std::int64_t bond_count() override { return sim_->bond_count(); }
  py::object saved_field(const std::string& name) override {
    const auto columns = solver::field_columns(scene_);
    const auto at = std::find(columns.begin(), columns.end(), name);
    if (at == columns.end())
      throw py::key_error("saved_field: no fields.csv column " + name +
                          " (the scene's [[output.fields]] give them)");
    const auto v = sim_->saved_field(static_cast<std::size_t>(at - columns.begin()));
    return v ? py::object(py::float_(*v)) : py::object(py::none());
  }
  py::array broken_bond_pairs() override {
    std::vector<double> mine;  // each break is recorded by one rank
    for (const auto& b : sim_->broken_bonds()) {
      mine.push_back(double(std::min(b.a, b.b)));
      mine.push_back(double(std::max(b.a, b.b)));
      mine.push_back(double(b.step));
    }
    const std::vector<double> all = comm_.size() > 1 ? comm_.all_gather(mine) : mine;
    std::vector<std::array<std::int64_t, 3>> rows;
    for (std::size_t k = 0; k + 2 < all.size(); k += 3)
      rows.push_back({static_cast<std::int64_t>(all[k]), static_cast<std::int64_t>(all[k + 1]),
                      static_cast<std::int64_t>(all[k + 2])});
    std::sort(rows.begin(), rows.end());
    py::array_t<std::int64_t> out({static_cast<py::ssize_t>(rows.size()), py::ssize_t{3}});
    auto w = out.mutable_unchecked<2>();
    for (std::size_t k = 0; k < rows.size(); ++k)
      for (py::ssize_t c = 0; c < 3; ++c)
        w(static_cast<py::ssize_t>(k), c) = rows[k][static_cast<std::size_t>(c)];
    return out;
  }
  std::int64_t broken_bonds() override {
    return comm_.sum(static_cast<long long>(sim_->broken_bonds().size()));
  }
  std::array<std::int64_t, 2> flow_totals() const override { return sim_->flow_totals(); }
  double critical_dt() const override { return sim_->stability().dt_critical; }
  std::vector<std::string> step_warnings() const override { return sim_->step_warnings(); }
  void checkpoint() override { sim_->checkpoint_now(*sink_); }

  py::dict energies() override {
    // The recomputation's forces and moments are put back as they were: they are the step's, except that the
    // bonds the step's forces found broken are gone from it (and with them the last pull the next step
    // applies).
    auto& p = sim_->particles();
    std::vector<std::vector<Real>> kept;
    const auto arrays = [&p] {
      std::vector<decltype(&p.fx)> a{&p.fx, &p.fy, &p.fz};
      if (p.with_rotation) a.insert(a.end(), {&p.tx, &p.ty, &p.tz});
      return a;
    }();
    for (const auto* a : arrays) kept.emplace_back(a->begin(), a->end());
    const auto values = sim_->ledger_values();
    for (std::size_t k = 0; k < arrays.size(); ++k)
      std::copy(kept[k].begin(), kept[k].end(), arrays[k]->begin());
    py::dict d;
    const auto& ledger = sim_->ledger();
    for (std::size_t t = 0; t < ledger.size(); ++t) d[py::str(ledger[t].name)] = values[t];
    return d;
  }

  py::dict walls() override {
    // Forces are this rank's shares: summed over the compute ranks (collective), alike on every rank.
    const auto& w = sim_->walls();
    std::vector<double> f;
    for (std::size_t k = 0; k < w.size(); ++k) f.insert(f.end(), w.force(k).begin(), w.force(k).end());
    if (comm_.size() > 1) comm_.sum_all(f);
    py::dict d;
    const auto& o = sim_->origin();
    for (std::size_t k = 0; k < w.size(); ++k) {
      py::dict e;
      const auto& x = w.point(k);
      e["position"] = py::make_tuple(x[0] + o[0], x[1] + o[1], x[2] + o[2]);
      e["normal"] = py::make_tuple(w.spec(k).normal[0], w.spec(k).normal[1], w.spec(k).normal[2]);
      e["force"] = py::make_tuple(f[3 * k], f[3 * k + 1], f[3 * k + 2]);
      e["removed"] = w.removed(k);
      d[py::str(w.spec(k).name)] = e;
    }
    return d;
  }

  py::dict state() override {
    py::dict d;
    d["step"] = step();
    d["time"] = time();
    d["dt"] = dt();
    return d;
  }

  py::array array(const std::string& name, py::handle owner) override {
    // A view (no copy) of this rank's owned particles' values: valid until the next step, which may
    // reorder and reallocate the arrays. Writing to it changes the run (velocities between steps).
    auto& p = sim_->particles();  // drops the cached kinetic energy: the caller may write
    const auto n = static_cast<py::ssize_t>(p.n_owned);
    auto view = [&](auto& v) {
      using T = typename std::decay_t<decltype(v)>::value_type;
      return py::array_t<T>({n}, {py::ssize_t(sizeof(T))}, v.data(), owner);
    };
    if (name == "x") return view(p.x);
    if (name == "y") return view(p.y);
    if (name == "z") return view(p.z);
    if (name == "vx") return view(p.vx);
    if (name == "vy") return view(p.vy);
    if (name == "vz") return view(p.vz);
    if (name == "fx") return view(p.fx);
    if (name == "fy") return view(p.fy);
    if (name == "fz") return view(p.fz);
    if (name == "radius") return view(p.radius);
    if (name == "inv_mass") return view(p.inv_mass);
    if (name == "id") return view(p.id);
    if (name == "tag") return view(p.tag);
    if (p.with_rotation) {
      if (name == "wx") return view(p.wx);
      if (name == "wy") return view(p.wy);
      if (name == "wz") return view(p.wz);
    }
    if (p.with_orientation) {
      if (name == "qw") return view(p.qw);
      if (name == "qx") return view(p.qx);
      if (name == "qy") return view(p.qy);
      if (name == "qz") return view(p.qz);
    }
    throw py::key_error("no particle array \"" + name +
                        "\" (x, y, z, vx, vy, vz, fx, fy, fz, radius, inv_mass, id, tag; wx, wy, wz with "
                        "rotation; qw, qx, qy, qz with particles.orientation)");
  }

  py::object gather(const std::vector<std::string>& names, py::handle owner, bool everywhere,
                    bool table) override {
    // Collective: (id, values) of every owned particle, all ranks', to rank 0 (every rank when everywhere)
    // sorted by id (as float64): one column per name, a 1-D array unless table.
    const std::size_t w = names.size() + 1;  // a row: the id, then the values
    std::vector<py::array_t<double>> columns;
    for (const auto& name : names)  // array() validates the name
      columns.push_back(array(name, owner).attr("astype")("float64").template cast<py::array_t<double>>());
    const auto& p = sim_->particles();
    std::vector<double> mine;
    mine.reserve(w * p.n_owned);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      mine.push_back(double(p.id[i]));
      for (const auto& c : columns) mine.push_back(c.at(static_cast<py::ssize_t>(i)));
    }
    const std::vector<double> all = comm_.size() > 1 ? comm_.all_gather(mine) : mine;
    if (comm_.rank() != 0 && !everywhere) return py::none();
    const std::size_t n = all.size() / w;
    std::vector<std::size_t> order(n);
    for (std::size_t k = 0; k < n; ++k) order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return all[w * a] < all[w * b]; });
    py::array_t<std::int64_t> ids(static_cast<py::ssize_t>(n));
    auto wi = ids.mutable_unchecked<1>();
    for (std::size_t k = 0; k < n; ++k)
      wi(static_cast<py::ssize_t>(k)) = static_cast<std::int64_t>(all[w * order[k]]);
    if (!table) {
      py::array_t<double> out(static_cast<py::ssize_t>(n));
      auto wo = out.mutable_unchecked<1>();
      for (std::size_t k = 0; k < n; ++k) wo(static_cast<py::ssize_t>(k)) = all[w * order[k] + 1];
      return py::make_tuple(ids, out);
    }
    py::array_t<double> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(names.size())});
    auto wo = out.mutable_unchecked<2>();
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t c = 0; c < names.size(); ++c)
        wo(static_cast<py::ssize_t>(k), static_cast<py::ssize_t>(c)) = all[w * order[k] + 1 + c];
    return py::make_tuple(ids, out);
  }

  std::string close() override {
    if (!client_) return {};
    const auto report = client_->finish();
    client_.reset();
    return report.error ? *report.error : std::string();
  }

 private:
  Scene scene_;
  solver::Comm comm_;
  std::unique_ptr<solver::Simulation<Real>> sim_;
  std::unique_ptr<io::OutputClient> client_;
  std::unique_ptr<basalt::run::ClientSink> sink_;
  std::optional<EsysWatch<Real>> watch_;  ///< the ESyS front end's rule and domain, once asked for
};

/// The Python object: the world's layout, and a Run on compute ranks.
class PySimulation {
 public:
  explicit PySimulation(const Options& o) {
    ensure_mpi();
    live_simulations().push_back(this);
    try {
      start(o);
    } catch (...) {
      forget();
      throw;
    }
  }
  ~PySimulation() {
    forget();
    if (mpi_finalized()) return;  // (closed at exit already, or MPI ended by someone else: nothing to do)
    try {
      close();
    } catch (...) {
    }
  }
  PySimulation(const PySimulation&) = delete;
  PySimulation& operator=(const PySimulation&) = delete;

  void start(const Options& o) {
    Scene scene = o.text ? solver::parse_scene_text(o.scene, "<scene text>", fs::current_path())
                         : solver::parse_scene(o.scene);
    if (!o.geometry.empty()) scene.geometry = o.geometry;
    if (!o.output.empty()) scene.output_dir = o.output;
    if (o.checkpoint_every >= 0) scene.checkpoint_every = o.checkpoint_every;
    if (!o.precision.empty()) scene.precision = o.precision;
    if (scene.precision != "double" && scene.precision != "float" && scene.precision != "mixed")
      throw InputError("precision = \"" + scene.precision + "\": double, float or mixed");
    if (scene.precision != "double") solver::refuse_single_precision(scene);
    if (scene.frames_every > 0 && !BASALT_WITH_VTK)
      throw InputError("output.frames_every: VTK frames are not in this build (BASALT_WITH_VTK=OFF)");
    if (scene.render_every > 0)
      throw InputError(
          "output.render_every: in-situ pictures are basalt-run's (--io-ranks); from Python, "
          "write checkpoints and draw them with basalt-view render");
    if (!fs::exists(scene.geometry))
      throw InputError("geometry file " + scene.geometry.string() + " does not exist");
    basalt::run::prepare_output_folder(scene.output_dir, MPI_COMM_WORLD);

    io::OutputConfig cfg;
    cfg.dir = scene.output_dir;
    cfg.checkpoint_every = scene.checkpoint_every;
    cfg.frames_every = scene.frames_every;
    cfg.fields_every = scene.fields.empty() ? 0 : 1;
    cfg.field_names = solver::field_columns(scene);
    cfg.max_frames_in_flight = static_cast<int>(scene.frames_in_flight);
    cfg.continue_on_error = scene.output_continue_on_error;
#if BASALT_WITH_VTK
    vtk_ = io::make_vtk_frame_writer(
        io::Units{scene.units.length, scene.units.time, scene.units.force, io::Units{}.mass}, -1.0);
#endif
    try {
      layout_ = io::split_ranks(MPI_COMM_WORLD, o.io_ranks);
    } catch (const std::invalid_argument& e) {
      throw InputError(e.what());
    }
    split_ = true;
    if (layout_.is_io) {
      io_ = true;
      // Serve the compute ranks' output until they close; the script then goes on with an idle object.
      io::IoServer server(layout_, cfg, vtk_);
      const auto report = server.run();
      if (report.error) io_error_ = *report.error;
      return;
    }
    if (scene.precision == "double")
      run_ = std::make_unique<RunOf<double>>(std::move(scene), layout_, cfg, vtk_, o);
    else
      run_ = std::make_unique<RunOf<float>>(std::move(scene), layout_, cfg, vtk_, o);
  }
  void forget() {
    auto& live = live_simulations();
    live.erase(std::remove(live.begin(), live.end(), this), live.end());
  }

  bool is_io_rank() const { return io_; }
  Run& run() {
    if (!run_) throw RunError(closed_ ? "the simulation is closed" : "an I/O rank runs no steps");
    return *run_;
  }

  /// Runs `steps` steps with the Python hooks [(every, callable(step) -> bool|None, reads velocities)]: False
  /// ends the run.
  /// A Python exception on any compute rank ends the run on every rank, with its message.
  std::int64_t run_steps(std::int64_t steps,
                         const std::vector<std::tuple<std::int64_t, py::function, bool>>& hooks) {
    if (is_io_rank()) return 0;
    auto& r = run();  // (a closed simulation: RunError)
    std::vector<solver::StepHook> calls;
    std::optional<py::error_already_set>
        raised;  // the Python exception of this rank, re-raised after the run
    for (const auto& [every, fn, velocities] : hooks) {
      if (every < 1) throw InputError("a callback's every must be >= 1");
      calls.push_back({every,
                       [&r, &raised, fn](std::int64_t step) {
                         std::optional<std::string> error;
                         bool go = true;
                         try {
                           const py::object result = fn(step);
                           go = result.is_none() || py::bool_(result);
                         } catch (py::error_already_set& e) {
                           error = e.what();
                           raised = std::move(e);
                         }
                         // One reduction: 2 = an error somewhere, 1 = a rank asks to stop.
                         double flag = error ? 2 : go ? 0 : 1;
                         if (r.comm().size() > 1) flag = r.comm().max(flag);
                         if (flag >= 2) {
                           const auto e = r.comm().size() > 1 ? r.comm().agree_error(error) : error;
                           throw RunError(fmt::format("callback at step {}: {}", step, *e));
                         }
                         return flag == 0;
                       },
                       velocities});
    }
    const std::int64_t first = r.step();
    try {
      return interruptible([&] { return r.run(steps, calls); });
    } catch (const solver::StopRequested&) {
      return r.step() - first;  // stopped by Ctrl-C, and Python's SIGINT handler did not raise
    } catch (const RunError&) {
      if (raised) throw *raised;  // this rank's own Python exception, with its type and traceback
      throw;
    }
  }

  py::list run_stages() {
    if (is_io_rank()) return py::list();
    auto& r = run();
    return interruptible([&] { return r.run_stages(); });
  }

  /// Runs body() with Ctrl-C asking the run to stop (solver::InterruptStopsRun): every compute rank stops at
  /// the same whole step, the next one where they agree on output errors (every 32 steps), with the
  /// deferred half-kick made. The SIGINT is then handed to Python's own handler, put back first (on every
  /// rank, whichever got it), which raises KeyboardInterrupt unless the script set another. A SIGINT after
  /// the ranks' last agreement is handed on at the end of the run, on its rank only, as Python would.
  /// Without a Python handler (SIG_IGN, SIG_DFL) SIGINT is left alone. Throws StopRequested when the run
  /// stopped and the handler did not raise.
  template <class Body>
  static auto interruptible(Body&& body) -> decltype(body()) {
    std::exception_ptr stopped;
    {
      solver::InterruptStopsRun interrupt;
      try {
        auto result = body();
        if (interrupt.restore() != 0) signal_python();
        return result;
      } catch (const solver::StopRequested&) {
        stopped = std::current_exception();
      }
    }
    signal_python();
    std::rethrow_exception(stopped);
  }
  /// A SIGINT for Python's own handler, run now (on the main thread; elsewhere Python runs it later).
  static void signal_python() {
    PyErr_SetInterrupt();
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }

  std::string close() {
    if (closed_) return {};
    closed_ = true;
    std::string error = run_ ? run_->close() : io_error_;
    run_.reset();
    if (split_) io::free_layout(layout_);
    split_ = false;
    return error;
  }

 private:
  io::RankLayout layout_;
  bool split_ = false;
  bool io_ = false;  ///< an I/O rank (its run() does nothing)
  bool closed_ = false;
  io::VtkFrameWriter vtk_;
  std::unique_ptr<Run> run_;
  std::string io_error_;
};

void close_live_simulations() {
  const auto live = live_simulations();  // (a copy: close() does not change the list, forget() does)
  for (auto* s : live) {
    try {
      s->close();
    } catch (...) {
    }
  }
}

}  // namespace

void bind_simulation(py::module_& m) {
  // Every process of mpirun's world waits here until all have come (MPI started if it was not): the ESyS
  // front end's scripts run on every rank, and a file rank 0 wrote is read by all only after it is written.
  m.def("world_barrier", [] {
    ensure_mpi();
    py::gil_scoped_release release;
    MPI_Barrier(MPI_COMM_WORLD);
  });
  py::class_<PySimulation>(m, "Simulation")
      .def(py::init([](const std::string& scene, bool text, const std::string& geometry,
                       const std::string& output, int io_ranks, const std::string& precision,
                       std::int64_t checkpoint_every, bool quiet, bool force_dt) {
             return std::make_unique<PySimulation>(Options{scene, text, geometry, output, precision, io_ranks,
                                                           checkpoint_every, quiet, force_dt});
           }),
           py::arg("scene"), py::arg("text") = false, py::arg("geometry") = "", py::arg("output") = "",
           py::arg("io_ranks") = 0, py::arg("precision") = "", py::arg("checkpoint_every") = -1,
           py::arg("quiet") = true, py::arg("force_dt") = false)
      .def_property_readonly("is_io_rank", &PySimulation::is_io_rank)
      .def("run", &PySimulation::run_steps, py::arg("steps"), py::arg("hooks") = py::list())
      .def("close", &PySimulation::close)
      .def("run_stages", &PySimulation::run_stages)
      .def_property_readonly("rank",
                             [](PySimulation& s) { return s.is_io_rank() ? -1 : s.run().comm().rank(); })
      .def_property_readonly("ranks",
                             [](PySimulation& s) { return s.is_io_rank() ? 0 : s.run().comm().size(); })
      .def_property_readonly("step", [](PySimulation& s) { return s.run().step(); })
      .def_property_readonly("time", [](PySimulation& s) { return s.run().time(); })
      .def_property_readonly("dt", [](PySimulation& s) { return s.run().dt(); })
      .def("set_dt", [](PySimulation& s, double dt) { s.run().set_dt(dt); })
      .def_property_readonly("total_particles", [](PySimulation& s) { return s.run().total_particles(); })
      .def_property_readonly("owned", [](PySimulation& s) { return s.run().owned(); })
      .def("array",
           [](py::object self, const std::string& name) {
             return self.cast<PySimulation&>().run().array(name, self);
           })
      .def(
          "gather",
          [](py::object self, const std::string& name, bool everywhere) {
            return self.cast<PySimulation&>().run().gather({name}, self, everywhere, false);
          },
          py::arg("name"), py::arg("everywhere") = false)
      .def(
          "gather_table",
          [](py::object self, const std::vector<std::string>& names, bool everywhere) {
            return self.cast<PySimulation&>().run().gather(names, self, everywhere, true);
          },
          py::arg("names"), py::arg("everywhere") = false)
      .def("kinetic_energy", [](PySimulation& s) { return s.run().kinetic_energy(); })
      .def("energies", [](PySimulation& s) { return s.run().energies(); })
      .def("walls", [](PySimulation& s) { return s.run().walls(); })
      .def("set_fixed_tags",
           [](PySimulation& s, std::vector<std::int64_t> t) { s.run().set_fixed_tags(std::move(t)); })
      .def("set_wall_velocity", [](PySimulation& s, const std::string& name,
                                   std::array<double, 3> v) { s.run().set_wall_velocity(name, v); })
      .def("move_wall_by", [](PySimulation& s, const std::string& name,
                              std::array<double, 3> u) { s.run().move_wall_by(name, u); })
      .def("remove_wall", [](PySimulation& s, const std::string& name) { s.run().remove_wall(name); })
      .def("add_wall", [](PySimulation& s, const std::string& name) { s.run().add_wall(name); })
      .def("set_wall_motion", [](PySimulation& s, const std::string& name,
                                 const std::string& keys) { s.run().set_wall_motion(name, keys); })
      .def(
          "state_changed",
          [](PySimulation& s, bool advance_history) { s.run().state_changed(advance_history); },
          py::arg("advance_history") = false)
      .def("set_body_force", [](PySimulation& s, const std::string& name,
                                const std::string& keys) { s.run().set_body_force(name, keys); })
      .def("body_forces", [](PySimulation& s) { return s.run().body_forces(); })
      .def("set_contact", [](PySimulation& s, const std::string& name,
                             const std::string& keys) { s.run().set_contact(name, keys); })
      .def("contacts", [](PySimulation& s) { return s.run().contacts(); })
      .def("insert", [](PySimulation& s, const std::string& keys) { return s.run().insert(keys); })
      .def("delete", [](PySimulation& s, const std::string& keys) { return s.run().remove(keys); })
      .def("bond_count", [](PySimulation& s) { return s.run().bond_count(); })
      .def("broken_bonds", [](PySimulation& s) { return s.run().broken_bonds(); })
      .def("broken_bond_pairs", [](PySimulation& s) { return s.run().broken_bond_pairs(); })
      .def("saved_field", [](PySimulation& s, const std::string& name) { return s.run().saved_field(name); })
      .def("flow_totals", [](PySimulation& s) { return s.run().flow_totals(); })
      .def_property_readonly("critical_dt", [](PySimulation& s) { return s.run().critical_dt(); })
      .def("esys_watch", [](PySimulation& s, double limit2, const std::array<double, 3>& lo,
                            const std::array<double, 3>& hi) { s.run().esys_watch(limit2, lo, hi); })
      .def("esys_watch_reset", [](PySimulation& s) { s.run().esys_watch_reset(); })
      .def("esys_watch_leave", [](PySimulation& s) { return s.run().esys_watch_leave(); })
      .def("esys_watch_rebuild_due", [](PySimulation& s) { return s.run().esys_watch_rebuild_due(); })
      .def("esys_watch_reference", [](PySimulation& s) { return s.run().esys_watch_reference(); })
      .def_property_readonly("step_warnings", [](PySimulation& s) { return s.run().step_warnings(); })
      .def("checkpoint", [](PySimulation& s) { s.run().checkpoint(); })
      .def("allreduce", [](PySimulation& s, double v, const std::string& op) {
        const auto& c = s.run().comm();
        if (c.size() == 1) return v;
        if (op == "sum") return c.sum(v);
        if (op == "max") return c.max(v);
        if (op == "min") return -c.max(-v);
        throw py::value_error("op: sum, max or min");
      });
}

}  // namespace basalt::python
