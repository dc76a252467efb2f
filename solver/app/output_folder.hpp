#pragma once
// The output folder of a run (basalt-run, Python's basalt.Simulation): created and probed before anything
// starts, so that an unwritable folder is named at once rather than at the first checkpoint.
#include <mpi.h>

#include <filesystem>

namespace basalt::run {

/// Collective over `world`: its rank 0 creates `dir` and checks it can write there; every rank throws the
/// same InputError (naming the folder) when it cannot.
void prepare_output_folder(const std::filesystem::path& dir, MPI_Comm world);

}  // namespace basalt::run
