#!/usr/bin/env bash
# The rig program links what runs at the servo rate and what builds it, and none of the research
# side's libraries: no deal.II, PETSc, SLEPc, Trilinos, p4est, HDF5, VTK, MPI, OpenSSL (libssl,
# libcrypto). Reads the program's shared libraries with ldd (its whole dependency closure), and
# checks that the research program does link deal.II and VTK, so that the check can fail.
# Usage: rig_links.sh KERF_RIG KERF
set -euo pipefail
KERF_RIG=$1 KERF=$2
research='lib(deal[._]ii|petsc|slepc|trilinos|teuchos|epetra|p4est|hdf5|vtk|mpi|open-pal|open-rte|ssl|crypto)[^ ]*\.so'
rig=$(ldd "$KERF_RIG")
if grep -Eio "$research" <<< "$rig"; then
  echo "kerf-rig links the research libraries above"
  exit 1
fi
full=$(ldd "$KERF")
for expected in 'deal[._]ii' vtk; do
  grep -Eiq "lib${expected}[^ ]*\.so" <<< "$full" || { echo "kerf does not link lib${expected}: the check reads nothing"; exit 1; }
done
echo "kerf-rig: $(wc -l <<< "$rig") shared libraries, none of deal.II, PETSc, VTK, MPI, OpenSSL (kerf: $(wc -l <<< "$full"))"
