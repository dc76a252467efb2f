"""What the scripts of tools/ share: where things are, how basalt-run is run, and how its outputs are read.

One module, standard library only at import time (numpy and h5py are imported by the functions that need
them), so that it also loads inside ESyS-Particle's embedded interpreter. A script of a sub-folder of tools/
finds it with

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    import basalt_tools as bt

What it holds (docs/ARCHITECTURE.md, "tools/"):
  * places: ROOT (the checkout), bin_dir()/binary() (a build's bin folder: --bin, else --build/bin, else
    ROOT/build/bin), reference_cube() (tests/data/cube1.geo or $BASALT_REFERENCE_DIR/cube1.geo);
  * MPI: mpi_settings() (the variables scripts/mpi-env.sh exports), mpi_env() (an environment for a job
    with some or all of them), mpirun();
  * basalt-run: basalt_run_command(), run() (a command, optionally under /usr/bin/time -v), parse_run()
    (the progress and summary lines of its standard output), read_fields() (the field series fields.csv);
  * /usr/bin/time -v: parse_time_v() (peak memory, wall, user and system seconds);
  * geometry and checkpoints: read_geo() (ESyS-Particle's .geo text), read_h5() and last_checkpoint()
    (Basalt's HDF5 geometry and checkpoints), read_esys_checkpoint() (ESyS-Particle's text checkpoints);
  * ESyS-Particle: the scripts of tools/esys run themselves again under `mpirun esysparticle`
    (esys_missing(), esys_relaunch(), esys_child(), parse_dims(), esys_simulation()).
"""
import glob
import math
import os
import re
import shutil
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
"""The repository's root (this file is ROOT/tools/basalt_tools.py)."""

# ---------------------------------------------------------------------------------------------- places


def repo_path(*parts):
    """A path inside the checkout: repo_path("scenes", "wave.toml")."""
    return os.path.join(ROOT, *parts)


def reference_dir(root=None):
    """The folder of the reference data: $BASALT_REFERENCE_DIR when set and not empty, else
    tests/data of `root` (default ROOT) (tests/data/README.md)."""
    return os.environ.get("BASALT_REFERENCE_DIR") or os.path.join(root or ROOT, "tests", "data")


def reference_cube(root=None):
    """The seed paper's 15 mm GenGeo cube: reference_dir(root)/cube1.geo (8,948 particles)."""
    return os.path.join(reference_dir(root), "cube1.geo")


def bin_dir(bin=None, build=None):
    """The folder of a build's executables: `bin` when given, else `build`/bin, else ROOT/build/bin."""
    if bin:
        return bin
    return os.path.join(build or repo_path("build"), "bin")


def binary(name, bin=None, build=None):
    """The path of executable `name` (basalt-run, basalt-pack, basalt-view) of a build (see bin_dir)."""
    return os.path.join(bin_dir(bin, build), name)


# ---------------------------------------------------------------------------------------------- MPI

# What scripts/mpi-env.sh exports, when that file cannot be read (a copy of tools/ without scripts/).
_MPI_ENV_FALLBACK = {
    "OMPI_ALLOW_RUN_AS_ROOT": "1",
    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    "OMPI_MCA_rmaps_base_oversubscribe": "1",
    "OMPI_MCA_mpi_yield_when_idle": "1",
    "OMPI_MCA_hwloc_base_binding_policy": "none",
    "HWLOC_COMPONENTS": "-gl",
}

RUN_AS_ROOT = ("OMPI_ALLOW_RUN_AS_ROOT", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "OMPI_MCA_rmaps_base_oversubscribe")
"""The settings that let mpirun start as root (CI) and start more ranks than cores."""

NO_GL = ("HWLOC_COMPONENTS",)
"""hwloc without its GL plugin, which opens X displays during MPI_Init (scripts/mpi-env.sh)."""

EAGER = {"OMPI_MCA_btl_vader_eager_limit": "65536", "OMPI_MCA_btl_vader_max_send_size": "65536"}
"""Open MPI's shared-memory eager limit that basalt-run sets for itself (solver/app/basalt_run.cpp,
prefer_eager_shared_memory_messages): given to peer codes so that every code's messages travel alike."""


def mpi_settings(path=None):
    """{name: value} of the `export NAME=VALUE` lines of scripts/mpi-env.sh (or of `path`)."""
    path = path or repo_path("scripts", "mpi-env.sh")
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        return dict(_MPI_ENV_FALLBACK)
    return {m.group(1): m.group(2).strip().strip("'\"")
            for m in re.finditer(r"^\s*export\s+([A-Za-z_][A-Za-z0-9_]*)=(\S*)", text, re.M)}


def mpi_env(names=None, ranks=None, eager=False, override=True, base=None, **extra):
    """An environment for an MPI job: `base` (default os.environ) with scripts/mpi-env.sh's settings.

    names: which of those settings (default all of them; () none; RUN_AS_ROOT, NO_GL name useful sets);
    override: False keeps a value the caller's environment already has (setdefault);
    ranks: when given and the ranks fit this machine's cores, OMPI_MCA_mpi_yield_when_idle=0, Open MPI's
      default for a job that is not oversubscribed (mpi-env.sh's yield costs 5-10 % at 2 ranks on 2 cores,
      docs/BENCHMARKS.md, "Two cores");
    eager: also EAGER, unless already set;
    extra: further variables, set last."""
    env = dict(os.environ if base is None else base)
    settings = mpi_settings()
    for k in (settings if names is None else names):
        if override:
            env[k] = settings.get(k, _MPI_ENV_FALLBACK.get(k, ""))
        else:
            env.setdefault(k, settings.get(k, _MPI_ENV_FALLBACK.get(k, "")))
    if ranks is not None and ranks <= (os.cpu_count() or 1):
        env["OMPI_MCA_mpi_yield_when_idle"] = "0"
    if eager:
        for k, v in EAGER.items():
            env.setdefault(k, v)
    env.update({k: str(v) for k, v in extra.items()})
    return env


def mpirun(ranks, launcher="mpirun", flag="-np"):
    """The launcher prefix for `ranks` ranks: ["mpirun", "-np", "N"]."""
    return [launcher, flag, str(ranks)]


# ---------------------------------------------------------------------------------------------- running


def basalt_run_command(exe, scene, *args, np=1, timed=False, launcher="mpirun", flag="-np"):
    """The command line of basalt-run `exe` on `scene` with `args`; under mpirun when np > 1, and under
    /usr/bin/time -v (outermost) when timed."""
    cmd = [exe, scene] + [str(a) for a in args]
    if np > 1:
        cmd = mpirun(np, launcher, flag) + cmd
    if timed:
        cmd = ["/usr/bin/time", "-v"] + cmd
    return cmd


class RunError(RuntimeError):
    """A command that exited with a non-zero status: .cmd, .returncode, .stdout, .stderr."""

    def __init__(self, cmd, p):
        self.cmd, self.returncode, self.stdout, self.stderr = cmd, p.returncode, p.stdout, p.stderr
        super().__init__(f"failed (exit {p.returncode}): {' '.join(cmd)}\n{(p.stdout or '')[-2000:]}\n"
                         f"{(p.stderr or '')[-2000:]}")


def run(cmd, timed=False, check=True, merge=False, **kw):
    """Runs `cmd` (a list), text output captured; returns the CompletedProcess. timed: under
    /usr/bin/time -v, its report parsed into p.time (parse_time_v) and removed from p.stderr. merge:
    standard error into standard output. check: raise RunError on a non-zero status."""
    if timed:
        cmd = ["/usr/bin/time", "-v"] + list(cmd)
    if merge:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)
    else:
        p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    p.time = parse_time_v(p.stderr or p.stdout or "") if timed else None
    if check and p.returncode != 0:
        raise RunError(list(cmd), p)
    return p


# ---------------------------------------------------------------------------------------------- basalt-run output

_NUM = r"([-+0-9.eEinfa]+)"  # a printed number (also nan / inf)

_HEADER = re.compile(r"^basalt-run (\S+): (\d+) particles, (\d+) bonds on (\d+) compute rank\(s\) \((\d+)x(\d+)x(\d+)\) "
                     r"\+ (\d+) I/O rank\(s\), (\d+) steps of dt = " + _NUM + r" (\S+) in (\w+)", re.M)
_CRITICAL = re.compile(r"^critical step: " + _NUM, re.M)
_FIELDS = re.compile(r"^fields: (.*) = (\d+) B/particle", re.M)
_DONE = re.compile(r"^done: (\d+) steps in ([0-9.]+) s \(([0-9.]+) steps/s, ([0-9.]+) M particle-steps/s\); "
                   r"start-up ([0-9.]+) s; (\d+) rebuilds", re.M)
_CPU = re.compile(r"^cpu time of the loop: ([0-9.]+) s per rank \(max\), ([0-9]+) % of the wall time", re.M)
_PHASES = re.compile(r"^time per step: (.*)$", re.M)
_PHASE = re.compile(r"\s*([a-z ]+?) ([0-9.]+) ms \(([0-9.]+) %\)")
_KINDS = re.compile(r"^forces by model kind: (.*)$", re.M)
_KIND_TIME = re.compile(r"\s*([a-z ]+?) ([0-9.]+) ms")
_ARRAYS = re.compile(r"^solver arrays: ([0-9.]+) MB \(([0-9]+) bytes per particle\)", re.M)
_BALANCE = re.compile(r"^balance: max/mean particles per rank ([0-9.]+) at start, ([0-9.]+) at the end; (\d+) re-balance",
                      re.M)
_KIND = re.compile(r"^  (checkpoints|frames|fields)\s+(\d+) files\s+([0-9.]+) MB\s+write\s+([0-9.]+) s", re.M)
_PICTURES = re.compile(r"^  pictures\s+(\d+) files\s+([0-9.]+) MB\s+draw\s+([0-9.]+) s \(([0-9.]+) s per picture, "
                       r"longest ([0-9.]+) s\); (\d+) of (\d+) drawn, (\d+) skipped", re.M)
_WAIT = re.compile(r"^  compute ranks waited ([0-9.]+) s for output(?:; I/O rank CPU time ([0-9.]+) s over ([0-9.]+) s wall)?",
                   re.M)


def parse_run(text):
    """The numbers of basalt-run's standard output (solver/app/basalt_run.cpp), as a dict; a key is
    missing when its line is (--quiet keeps the summary; a failed run has no "done:" line).

    header:   version, particles, bonds, compute_ranks, dims (x, y, z), io_ranks, steps, dt, time_unit,
              precision
    critical_step   (the "critical step:" line, when the scene has a finite one)
    field_bytes     (the "fields: ... = N B/particle" line)
    done:     loop_steps, loop_s, steps_per_s, particle_steps_per_s (particles x steps / loop seconds),
              startup_s, rebuilds
    cpu_s, cpu_percent      (the loop's CPU time per rank, max, and its share of the wall time)
    time_per_step           (that line's text after the colon), phases {name: (ms per step, % of loop)}
    force_kinds             {bond|pair|wall|body force: ms per step} (the "forces by model kind" line)
    arrays_mb, bytes_per_particle   (the solver's arrays)
    balance_start, balance_end, rebalances   (several ranks)
    output {checkpoints|frames|fields: (files, MB, write s)}, compute_wait_s, io_cpu_s, io_wall_s
    pictures: pictures_files, draw_s, per_picture_s, longest_s, drawn, due, skipped."""
    r = {}
    m = _HEADER.search(text)
    if m:
        r.update(version=m.group(1), particles=int(m.group(2)), bonds=int(m.group(3)),
                 compute_ranks=int(m.group(4)), dims=tuple(int(m.group(k)) for k in (5, 6, 7)),
                 io_ranks=int(m.group(8)), steps=int(m.group(9)), dt=float(m.group(10)), time_unit=m.group(11),
                 precision=m.group(12))
    m = _CRITICAL.search(text)
    if m:
        r["critical_step"] = float(m.group(1))
    m = _FIELDS.search(text)
    if m:
        r["field_bytes"] = int(m.group(2))
    m = _DONE.search(text)
    if m:
        r.update(loop_steps=int(m.group(1)), loop_s=float(m.group(2)), steps_per_s=float(m.group(3)),
                 particle_steps_per_s=float(m.group(4)) * 1e6, startup_s=float(m.group(5)),
                 rebuilds=int(m.group(6)))
    m = _CPU.search(text)
    if m:
        r.update(cpu_s=float(m.group(1)), cpu_percent=float(m.group(2)))
    m = _PHASES.search(text)
    if m:
        r["time_per_step"] = m.group(1).strip()
        r["phases"] = {p.group(1).strip(): (float(p.group(2)), float(p.group(3)))
                       for p in _PHASE.finditer(m.group(1))}
    m = _KINDS.search(text)
    if m:
        r["force_kinds"] = {k.group(1).strip(): float(k.group(2)) for k in _KIND_TIME.finditer(m.group(1))}
    m = _ARRAYS.search(text)
    if m:
        r.update(arrays_mb=float(m.group(1)), bytes_per_particle=int(m.group(2)))
    m = _BALANCE.search(text)
    if m:
        r.update(balance_start=float(m.group(1)), balance_end=float(m.group(2)), rebalances=int(m.group(3)))
    kinds = {k.group(1): (int(k.group(2)), float(k.group(3)), float(k.group(4))) for k in _KIND.finditer(text)}
    if kinds:
        r["output"] = kinds
    m = _PICTURES.search(text)
    if m:
        r.update(pictures_files=int(m.group(1)), draw_s=float(m.group(3)), per_picture_s=float(m.group(4)),
                 longest_s=float(m.group(5)), drawn=int(m.group(6)), due=int(m.group(7)), skipped=int(m.group(8)))
    m = _WAIT.search(text)
    if m:
        r["compute_wait_s"] = float(m.group(1))
        if m.group(2):
            r.update(io_cpu_s=float(m.group(2)), io_wall_s=float(m.group(3)))
    return r


def read_fields(path):
    """basalt-run's field series: {column: [values]} of `path` (a fields.csv, or a run's output folder
    holding one), in file order. "step" values are int; the others float, an empty cell (a field not saved
    at that step) and "nan" being nan."""
    if os.path.isdir(path):
        path = os.path.join(path, "fields.csv")
    with open(path) as f:
        lines = [line.rstrip("\n") for line in f if line.strip()]
    if not lines:
        return {}
    header = lines[0].split(",")
    cols = {name: [] for name in header}
    for line in lines[1:]:
        cells = line.split(",")
        for name, v in zip(header, cells):
            if name == "step":
                cols[name].append(int(v))
            else:
                cols[name].append(float(v) if v not in ("", "nan") else math.nan)
        for name in header[len(cells):]:
            cols[name].append(math.nan)
    return cols


# ---------------------------------------------------------------------------------------------- /usr/bin/time -v


def _clock(text):
    """Seconds of "h:mm:ss" or "m:ss.ss"."""
    parts = [float(x) for x in text.split(":")]
    return sum(v * 60 ** (len(parts) - 1 - i) for i, v in enumerate(parts))


def parse_time_v(text):
    """GNU time's -v report (in a command's standard error) as a dict: max_rss_kb (the largest when several
    processes reported, e.g. one per rank), wall_s, user_s, sys_s, exit_status; a key is missing when its line
    is. Empty dict when there is no report."""
    r = {}
    rss = [int(v) for v in re.findall(r"Maximum resident set size \(kbytes\): (\d+)", text)]
    if rss:
        r["max_rss_kb"] = max(rss)
    m = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text)
    if m:
        r["wall_s"] = _clock(m.group(1))
    for key, label in (("user_s", "User time"), ("sys_s", "System time")):
        m = re.search(label + r" \(seconds\): ([0-9.]+)", text)
        if m:
            r[key] = float(m.group(1))
    m = re.search(r"Exit status: (\d+)", text)
    if m:
        r["exit_status"] = int(m.group(1))
    return r


# ---------------------------------------------------------------------------------------------- geometry, checkpoints


class GeoError(Exception):
    """A .geo file that cannot be read; the message names the file and line."""


def read_geo(path):
    """Reads ESyS-Particle's LSMGeometry 1.2 text format (.geo): returns (box_lo, box_hi, particles, bonds).

    particles: list of (id, x, y, z, r, tag); bonds: list of (id1, id2, tag). The box is the file's
    BoundingBox, or the particles' extent when it has none. Raises GeoError naming file and line."""
    try:
        with open(path) as f:
            lines = f.read().split("\n")
    except OSError as e:
        raise GeoError(f"{path}: cannot read: {e.strerror}")
    pos = 0

    def next_line(what):
        nonlocal pos
        while pos < len(lines) and not lines[pos].strip():
            pos += 1
        if pos >= len(lines):
            raise GeoError(f"{path}: unexpected end of file, expected {what}")
        pos += 1
        return pos, lines[pos - 1].split()

    def numbers(lineno, words, count, what):
        if len(words) < count:
            raise GeoError(f"{path}:{lineno}: expected {count} numbers for {what}, got '{' '.join(words)}'")
        try:
            return [float(w) for w in words[:count]]
        except ValueError:
            raise GeoError(f"{path}:{lineno}: non-numeric {what}: '{' '.join(words)}'")

    lineno, words = next_line("LSMGeometry header")
    if words[:1] != ["LSMGeometry"]:
        raise GeoError(f"{path}:{lineno}: not an LSMGeometry file (first line '{' '.join(words)}')")
    box_lo = box_hi = None
    while True:
        lineno, words = next_line("BeginParticles")
        if words[0] == "BoundingBox":
            b = numbers(lineno, words[1:], 6, "BoundingBox")
            box_lo, box_hi = b[:3], b[3:]
        elif words[0] == "BeginParticles":
            break
    lineno, words = next_line("particle type")
    if words[0] != "Simple":
        raise GeoError(f"{path}:{lineno}: particle type '{words[0]}' unsupported (only Simple)")
    lineno, words = next_line("particle count")
    count = int(numbers(lineno, words, 1, "particle count")[0])
    particles = []
    for _ in range(count):
        lineno, words = next_line("a particle line")
        x, y, z, r, pid, tag = numbers(lineno, words, 6, "particle 'x y z r id tag'")
        if r <= 0:
            raise GeoError(f"{path}:{lineno}: radius must be positive, got {r}")
        particles.append((int(pid), x, y, z, r, int(tag)))
    lineno, words = next_line("EndParticles")
    if words[0] != "EndParticles":
        raise GeoError(f"{path}:{lineno}: expected EndParticles, got '{' '.join(words)}'")
    bonds = []
    if pos < len(lines):
        try:
            lineno, words = next_line("BeginConnect")
        except GeoError:
            words = []
        if words[:1] == ["BeginConnect"]:
            lineno, words = next_line("bond count")
            nb = int(numbers(lineno, words, 1, "bond count")[0])
            ids = {p[0] for p in particles}
            for _ in range(nb):
                lineno, words = next_line("a bond line")
                a, b, t = (int(v) for v in numbers(lineno, words, 3, "bond 'id1 id2 tag'"))
                if a not in ids or b not in ids:
                    raise GeoError(f"{path}:{lineno}: bond {a}-{b} names an unknown particle id")
                bonds.append((a, b, t))
    if box_lo is None:
        box_lo = [min(p[i + 1] - p[4] for p in particles) for i in range(3)]
        box_hi = [max(p[i + 1] + p[4] for p in particles) for i in range(3)]
    return box_lo, box_hi, particles, bonds


def geo_particle_count(path):
    """The particle count of a .geo file (the line after "Simple"), without reading the particles."""
    with open(path) as f:
        for line in f:
            if line.strip() == "Simple":
                return int(next(f))
    raise GeoError(f"{path}: not a .geo file (no 'Simple' line)")


def read_h5(path, *names):
    """Datasets of a Basalt HDF5 geometry or checkpoint (docs/formats.md) as numpy arrays, in the file's
    order: read_h5(f, "particles/id", "particles/position") -> [ids, positions]. A name missing from the file
    gives None. Needs h5py (Debian's python3-h5py)."""
    try:
        import h5py
    except ImportError:
        raise SystemExit("error: h5py is missing (apt-get install python3-h5py)")
    with h5py.File(path, "r") as f:
        return [f[n][()] if n in f else None for n in names]


def last_checkpoint(run_dir):
    """The last checkpoint (ckpt_NNNNNN.h5, highest step) of a run's output folder, or None."""
    files = sorted(glob.glob(os.path.join(run_dir, "ckpt_*.h5")))
    return files[-1] if files else None


def read_esys_checkpoint(prefix, step, workers=1):
    """ESyS-Particle's text checkpoint after `step` steps, PREFIX_t=STEP_W.txt for workers W = 1..workers
    (prefix: e.g. "DIR/cp" for the CheckPointPrms fileNamePrefix "cp"): returns (rows, bonds), rows
    {particle id: [the particle line's numbers]} (x y z at 0-2, radius 3, id 4, mass 6, initial position
    7-9, velocity 13-15, force 16-18, rotating spheres' quaternion 22-25 and angular velocity 26-28),
    bonds the sum of the counts after each "Bonded" line."""
    rows, bonds = {}, 0
    for w in range(1, workers + 1):
        with open(f"{prefix}_t={step}_{w}.txt") as f:
            lines = [line.split() for line in f.read().split("\n") if line.strip()]
        for words in lines[1:1 + int(lines[0][0])]:
            v = [float(x) for x in words]
            rows[int(v[4])] = v
        for i, words in enumerate(lines):
            if words == ["Bonded"]:
                bonds += int(lines[i + 1][0])
    return rows, bonds


# ---------------------------------------------------------------------------------------------- ESyS-Particle

ESYS_CHILD_ENV = "BASALT_ESYS_CHILD"
"""Set to 1 in the environment of a script run again under esysparticle."""


def esys_child():
    """True inside the run under `mpirun esysparticle` that esys_relaunch() started."""
    return os.environ.get(ESYS_CHILD_ENV) == "1"


def esys_missing():
    """The executables an ESyS-Particle run needs that are not on PATH (esysparticle, mpirun)."""
    return [exe for exe in ("esysparticle", "mpirun") if shutil.which(exe) is None]


def esys_env():
    """The environment of the run under esysparticle: ESYS_CHILD_ENV=1, and mpirun's root and
    oversubscription settings unless the caller's environment has them."""
    return mpi_env(RUN_AS_ROOT, override=False, **{ESYS_CHILD_ENV: "1"})


def esys_command(script, ranks, args=()):
    """["mpirun", "-np", RANKS, "esysparticle", SCRIPT, ARGS...]: the script again, inside ESyS's
    interpreter, as 1 master + RANKS - 1 workers."""
    return mpirun(ranks) + ["esysparticle", os.path.abspath(script)] + list(args)


def esys_relaunch(script, ranks, args=(), cwd=None, echo=True):
    """Runs the script again under `mpirun esysparticle` (esys_command, esys_env) in `cwd`, printing the
    command first when echo; returns its exit status."""
    cmd = esys_command(script, ranks, args)
    if echo:
        print("running:", " ".join(cmd), flush=True)
    return subprocess.call(cmd, env=esys_env(), cwd=cwd)


def parse_dims(text):
    """'nx,ny,nz' -> [nx, ny, nz], three positive integers; ValueError otherwise."""
    dims = [int(v) for v in text.split(",")]
    if len(dims) != 3 or min(dims) < 1:
        raise ValueError(text)
    return dims


def esys_simulation(dims, particle_type, grid_spacing, verlet_dist, lo, hi, dt=None, steps=None):
    """ESyS-Particle's LsmMpi set-up the scripts share: `dims[0] * dims[1] * dims[2]` workers in grid `dims`,
    neighbour search for `particle_type` ("NRotSphere", "RotSphere"), the spatial domain lo..hi, and when
    given the time step and number of steps. Only inside esysparticle."""
    from esys.lsm import LsmMpi
    from esys.lsm.util import Vec3, BoundingBox
    sim = LsmMpi(numWorkerProcesses=dims[0] * dims[1] * dims[2], mpiDimList=list(dims))
    sim.initNeighbourSearch(particleType=particle_type, gridSpacing=grid_spacing, verletDist=verlet_dist)
    sim.setSpatialDomain(BoundingBox(Vec3(*lo), Vec3(*hi)))
    if dt is not None:
        sim.setTimeStepSize(dt)
    if steps is not None:
        sim.setNumTimeSteps(steps)
    return sim


def interp(t, y, x):
    """y at x by linear interpolation in the increasing samples t (held constant beyond the ends)."""
    lo, hi = 0, len(t) - 1
    if x <= t[0]:
        return y[0]
    if x >= t[-1]:
        return y[-1]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if t[mid] <= x:
            lo = mid
        else:
            hi = mid
    w = (x - t[lo]) / (t[hi] - t[lo])
    return (1 - w) * y[lo] + w * y[hi]
