# Sourced by Basalt's scripts: lets Open MPI run as root (CI runs as root) and run more ranks
# than cores (CI has 2 cores; tests go up to 8 ranks). Scripts set these, never CMake.
export OMPI_ALLOW_RUN_AS_ROOT=1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
# An idle rank should yield its core instead of spinning (2-core machines).
export OMPI_MCA_mpi_yield_when_idle=1
