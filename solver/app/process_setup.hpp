#pragma once
// How a process that runs Basalt's solver sets itself up before MPI_Init: basalt-run's main and the Python
// package's first Simulation (python/src/simulation.cpp) make the same calls, so that both run alike.

namespace basalt::run {

/// glibc keeps freed memory in the heap and raises its mmap threshold to the largest block freed (up to
/// 32 MB), so the arrays rebuilt at every neighbour-list rebuild come back from a heap that only grows: the
/// 60 mm wave cube's two ranks went from 274 to 401 MB of RSS in 2,000 steps (25 rebuilds), the 9.47 M cube
/// from 2.77 to 3.00 GB. A fixed threshold of 1 MB (blocks above it mmapped, returned to the system when
/// freed) and trimming above 1 MB keep them at 220 MB and flat (docs/BENCHMARKS.md, "Memory over a run").
/// MALLOC_MMAP_THRESHOLD_ / MALLOC_TRIM_THRESHOLD_ in the environment still win.
void bound_heap_growth();

/// Open MPI's shared-memory transport (btl vader) sends a message above 4 KiB by rendezvous: the
/// receiver reads the rest from the sender's memory once both have met in an MPI call. The per-step
/// ghost refresh is 10-60 kB each way in the benchmark scenes (e.g. 600 ghosts x 9 values for a granular
/// pile cut in two), so every step paid that meeting. Sent eagerly (copied into shared memory at the
/// send, taken at the wait), 2-rank runs took 0.90x the time on the wave cube and 0.98x on the granular
/// piles (docs/BENCHMARKS.md, "Ghost messages sent eagerly"). Set only where the user has not (mpirun
/// --mca, the environment, which win); other MPI libraries and other transports ignore these names.
/// Before MPI_Init, which reads them.
void prefer_eager_shared_memory_messages();

}  // namespace basalt::run
