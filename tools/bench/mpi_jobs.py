"""The environment of a benchmark's MPI job (tools/bench/ucs_bench.py, granular_bench.py).

scripts/mpi-env.sh makes idle ranks yield their core (the tests run up to 8 ranks on 2 cores); a job that
fits the cores takes Open MPI's own default for a job that is not oversubscribed, no yield (the yields cost
5-10 % at 2 ranks on 2 cores: docs/BENCHMARKS.md, "Two cores"). Every code timed gets the same, except
ESyS-Particle, whose master waits on its worker and would take the other core spinning. Every code run
through mpi_env() also gets basalt-run's eager limit for shared-memory messages.
"""
import os


def mpi_env(ranks):
    """os.environ, without Open MPI's yield when `ranks` fit this machine's cores."""
    env = dict(os.environ)
    if ranks <= (os.cpu_count() or 1):
        env["OMPI_MCA_mpi_yield_when_idle"] = "0"
    # basalt-run sends messages up to 64 KiB eagerly through shared memory (solver/app/basalt_run.cpp,
    # prefer_eager_shared_memory_messages); the peers get the same from the environment, so every code's
    # messages travel alike (LAMMPS's 2-rank time on the 20k pile: no measurable change, 6 pairs).
    env.setdefault("OMPI_MCA_btl_vader_eager_limit", "65536")
    env.setdefault("OMPI_MCA_btl_vader_max_send_size", "65536")
    return env
