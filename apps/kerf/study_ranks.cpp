#include "apps/kerf/study_ranks.hpp"

#include "reference/mpi_processes.hpp"

#include <mpi.h>

#include <cstdlib>
#include <stdexcept>

namespace kerf {

namespace {

void finalize_mpi() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

bool launched_by_mpi() { return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr; }

} // namespace

StudyRanks::StudyRanks() {
  if (!launched_by_mpi()) return;
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    if (MPI_Init(nullptr, nullptr) != MPI_SUCCESS) throw std::runtime_error("kerf study: MPI_Init failed");
    std::atexit(finalize_mpi);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m_size);
  // PETSc's initialisation is collective over MPI_COMM_WORLD, and a reference solve initialises it
  // on first use (reference/mpi_processes.hpp) — on one rank only, the others would never join.
  // Every rank initialises it here, together, before any run.
  if (m_size > 1) reference::initialize_petsc();
}

StudyExecution StudyRanks::execution(int jobs) const {
  StudyExecution e;
  e.jobs = jobs;
  e.rank = m_rank;
  e.ranks = m_size;
  if (m_size > 1)
    e.synchronise = [](int value) {
      int sum = 0;
      if (MPI_Allreduce(&value, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD) != MPI_SUCCESS)
        throw std::runtime_error("kerf study: MPI_Allreduce failed");
      return sum;
    };
  return e;
}

} // namespace kerf
