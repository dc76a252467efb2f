#pragma once
// The output report of a run: every rank's share, reduced over the world at the end.
#include <mpi.h>

#include "basalt/io/io_ranks.hpp"

namespace basalt::io::detail {

/// Sums and maxima of the report over every rank of `comm`; the first error text travels too.
/// Collective over `comm`.
OutputReport reduce_report(MPI_Comm comm, const OutputReport& mine);

}  // namespace basalt::io::detail
