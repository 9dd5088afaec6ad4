#pragma once
// A study under MPI: `mpirun -np N kerf study …` spreads the runs of one study over the
// ranks (study_runner.hpp, StudyExecution). Compiled into the kerf program only — the one target
// that links MPI::MPI_CXX; kerf_experiments and realtime/ know nothing of MPI.

#include "experiments/study/study_runner.hpp"

namespace kerf {

/// This process's place among the ranks of an MPI launch. MPI is initialised only when an MPI
/// launcher started the process (Open MPI's OMPI_COMM_WORLD_SIZE, or PMI_SIZE, in the
/// environment); a plain `kerf study` is one rank and never touches MPI. With more than one rank,
/// every rank then initialises PETSc together (its initialisation is collective over
/// MPI_COMM_WORLD; a reference solve on one rank would otherwise initialise it alone and wait for
/// the others). MPI_Finalize is registered with std::atexit before PETSc registers its own
/// finaliser (reference/mpi_processes.cpp), so PETSc finalises first (atexit runs in reverse order).
class StudyRanks {
public:
  StudyRanks();
  [[nodiscard]] int rank() const { return m_rank; }
  [[nodiscard]] int size() const { return m_size; }
  /// The execution of a study on these ranks with `jobs` threads each: synchronise is
  /// MPI_Allreduce(MPI_SUM) on MPI_COMM_WORLD (also the barrier).
  [[nodiscard]] StudyExecution execution(int jobs) const;

private:
  int m_rank = 0;
  int m_size = 1;
};

} // namespace kerf
