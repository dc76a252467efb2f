# Sourced by Basalt's scripts: lets Open MPI run as root (CI runs as root) and run more ranks
# than cores (CI has 2 cores; tests go up to 8 ranks). Scripts set these, never CMake.
export OMPI_ALLOW_RUN_AS_ROOT=1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
# An idle rank should yield its core instead of spinning (2-core machines).
export OMPI_MCA_mpi_yield_when_idle=1
# No pinning: on a shared 2-core machine, ranks pinned to busy cores ran 2-4x slower
# (docs/paper-study.md). Same as `mpirun --bind-to none`.
export OMPI_MCA_hwloc_base_binding_policy=none
# hwloc's GL plugin opens X displays :0-:9 during MPI_Init; an X server that comes and goes
# there (basalt-view's Xvfb, another job's) then kills the rank at start-up.
export HWLOC_COMPONENTS=-gl
