# kerf reference --np 2 as a user runs it (3 samples and the pull's end at t = 1.6 s, a vertex of
# the motion: 4 loads; adaptive sampling off so that the count is known; linear tetrahedra, few enough DOFs for the automatic choice to solve them directly with
# MUMPS — clay_pull's own quadratic ones, 63 498 DOFs, are above the distributed direct limit:
# docs/reference.md, "MPI"): the command re-launches itself under mpirun -np 2;
# rank 0 alone prints the progress (each sample line once) and writes the profile, the manifest
# (2 MPI processes) and the ParaView collection of .pvtu records with one .vtu piece per process.
# (That the distributed profile equals the serial one is test_distributed.cpp's check.)
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${KERF} reference clay_pull --degree 1 --samples 3 --adaptive 0 --np 2 -o ${WORK}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kerf reference clay_pull --np 2 failed (${rc}):\n${out}\n${err}")
endif()
foreach(f profile.csv manifest.json fields.pvd fields/step_0003.pvtu fields/step_0003.0.vtu fields/step_0003.1.vtu)
  if(NOT EXISTS ${WORK}/${f})
    message(FATAL_ERROR "kerf reference --np 2 did not write ${f}")
  endif()
endforeach()
file(STRINGS ${WORK}/profile.csv lines)
list(LENGTH lines n)
if(NOT n EQUAL 5)
  message(FATAL_ERROR "profile.csv has ${n} lines, expected a header and 4 rows")
endif()
file(READ ${WORK}/manifest.json manifest)
if(NOT manifest MATCHES "\"mpi_processes\": 2")
  message(FATAL_ERROR "manifest does not record 2 MPI processes")
endif()
string(REGEX MATCHALL "sample 4/4" last "${err}")
list(LENGTH last count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one progress line for sample 4/4 (rank 0 only), got ${count}:\n${err}")
endif()
string(REGEX MATCHALL "samples solved" summary "${out}")
list(LENGTH summary count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one summary line (rank 0 only), got ${count}:\n${out}")
endif()
