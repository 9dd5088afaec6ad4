#include "reference/mpi_processes.hpp"

#include <petscsys.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace kerf::reference {

namespace {

void finalize_petsc() {
  PetscBool finalized = PETSC_FALSE;
  PetscFinalized(&finalized);
  if (!finalized) PetscFinalize();
}

bool mpi_running() {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  return initialized != 0 && finalized == 0;
}

} // namespace

int mpirun_process_count() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* value = std::getenv(name)) return std::atoi(value);
  return 0;
}

void initialize_petsc() {
  PetscBool initialized = PETSC_FALSE;
  PetscInitialized(&initialized);
  if (initialized) return;
  const PetscErrorCode code = PetscInitializeNoArguments();
  if (code != 0) throw std::runtime_error("PetscInitializeNoArguments failed with PETSc error " + std::to_string(code));
  std::atexit(finalize_petsc);
}

MpiProcesses mpi_processes() {
  if (mpirun_process_count() > 1) initialize_petsc();
  if (!mpi_running()) return {};
  MpiProcesses p;
  MPI_Comm_rank(MPI_COMM_WORLD, &p.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &p.count);
  return p;
}

void wait_for_processes() {
  if (mpi_processes().count > 1) MPI_Barrier(MPI_COMM_WORLD);
}

} // namespace kerf::reference
