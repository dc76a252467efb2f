"""The environment of a benchmark's MPI job (tools/bench/ucs_bench.py, granular_bench.py).

scripts/mpi-env.sh makes idle ranks yield their core (the tests run up to 8 ranks on 2 cores); a job that
fits the cores takes Open MPI's own default for a job that is not oversubscribed, no yield (the yields cost
5-10 % at 2 ranks on 2 cores: docs/BENCHMARKS.md, "Two cores"). Every code timed gets the same, except
ESyS-Particle, whose master waits on its worker and would take the other core spinning.
"""
import os


def mpi_env(ranks):
    """os.environ, without Open MPI's yield when `ranks` fit this machine's cores."""
    env = dict(os.environ)
    if ranks <= (os.cpu_count() or 1):
        env["OMPI_MCA_mpi_yield_when_idle"] = "0"
    return env
