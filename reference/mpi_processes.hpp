#pragma once
// The MPI processes of a reference run (issue 3, "mpirun -np N kerf reference … runs distributed").
// kerf's programs have no MPI main: MPI (through PETSc) is initialised on first use, and only when
// the program was launched by mpirun with more than one process (or PETSc is needed anyway, see
// initialize_petsc). A program started on its own never initialises MPI, so the serial reference
// keeps its start-up time and its UMFPACK path.
//
// Plain C++: no MPI, PETSc or deal.II in this header.

namespace kerf::reference {

/// This process's place among the processes of MPI_COMM_WORLD.
struct MpiProcesses {
  int rank = 0;  ///< 0 … count − 1; rank 0 writes the run's files and prints its progress
  int count = 1; ///< 1 when the program was not launched by mpirun with N > 1
};

/// The processes of this run. Launched by mpirun (Open MPI's OMPI_COMM_WORLD_SIZE or PMI's
/// PMI_SIZE in the environment) with more than one process: initialises PETSc and MPI on first
/// call (collective: every process calls it) and returns MPI_COMM_WORLD's rank and size. Otherwise
/// {0, 1} without touching MPI (unless MPI is already initialised, then MPI_COMM_WORLD's values).
MpiProcesses mpi_processes();

/// The process count mpirun announces to the processes it starts (Open MPI's
/// OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_SIZE in the environment); 0 when not launched by mpirun.
int mpirun_process_count();

/// Initialises PETSc (and with it MPI) once per program; PetscFinalize runs at exit.
void initialize_petsc();

/// Waits until every process has reached this call; no-op on one process.
void wait_for_processes();

} // namespace kerf::reference
