# `mpirun -np 2 kerf study` gives the single-process tables and cache (issue 7): the coarse
# two-scene study run serially, then on two ranks (the two reference solves and the model runs
# spread over them), compared cell by cell apart from the cost columns (to round-off,
# compare_tables.py); the two caches hold the same entries (same key, same profile, a manifest);
# a second two-rank run reuses the cache (no reference solve).
# Open MPI refuses root without OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM) (set by the test's ENVIRONMENT);
# two ranks on a busy 2-core machine need --oversubscribe. One timing run per model (--timing-runs 1):
# the cost columns are not compared, and the pass still runs on the ranks.
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${KERF} study ${STUDY} -o ${WORK}/serial --jobs 1 --timing-runs 1 RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "serial study failed (${rc}): ${out} ${err}")
endif()
if(NOT out MATCHES "2 reference solve\\(s\\) run .*1 job\\(s\\) x 1 rank\\(s\\)")
  message(FATAL_ERROR "expected 2 reference solves on 1 rank: ${out}")
endif()
set(mpirun ${MPIRUN} --oversubscribe -np 2 ${KERF} study ${STUDY} -o ${WORK}/mpi --jobs 1 --timing-runs 1)
execute_process(COMMAND ${mpirun} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mpirun study failed (${rc}): ${out} ${err}")
endif()
if(NOT out MATCHES "2 reference solve\\(s\\) run .*1 job\\(s\\) x 2 rank\\(s\\)")
  message(FATAL_ERROR "expected 2 reference solves on 2 ranks: ${out}")
endif()
execute_process(COMMAND /usr/bin/python3 ${COMPARE} ${WORK}/serial/study.csv ${WORK}/mpi/study.csv
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "MPI and serial tables differ: ${out} ${err}")
endif()
message(STATUS "study.csv: ${out}")

# The same cache: the same entries (directory names are the keys), each with the same key.txt,
# the same profile apart from its cost column, and a manifest — whichever rank solved it.
file(GLOB serial_entries RELATIVE ${WORK}/serial/cache ${WORK}/serial/cache/*)
file(GLOB mpi_entries RELATIVE ${WORK}/mpi/cache ${WORK}/mpi/cache/*)
list(SORT serial_entries)
list(SORT mpi_entries)
list(LENGTH serial_entries count)
if(NOT count EQUAL 2 OR NOT serial_entries STREQUAL mpi_entries)
  message(FATAL_ERROR "caches differ: serial {${serial_entries}}, mpi {${mpi_entries}}")
endif()
foreach(entry ${serial_entries})
  file(READ ${WORK}/serial/cache/${entry}/key.txt serial_key)
  file(READ ${WORK}/mpi/cache/${entry}/key.txt mpi_key)
  if(NOT serial_key STREQUAL mpi_key)
    message(FATAL_ERROR "${entry}: key.txt differs:\n${serial_key}\n${mpi_key}")
  endif()
  if(NOT EXISTS ${WORK}/mpi/cache/${entry}/manifest.json OR NOT EXISTS ${WORK}/serial/cache/${entry}/manifest.json)
    message(FATAL_ERROR "${entry}: a manifest.json is missing")
  endif()
  execute_process(COMMAND /usr/bin/python3 ${COMPARE} ${WORK}/serial/cache/${entry}/profile.csv ${WORK}/mpi/cache/${entry}/profile.csv
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${entry}: MPI and serial reference profiles differ: ${out} ${err}")
  endif()
endforeach()

execute_process(COMMAND ${mpirun} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "0 reference solve\\(s\\) run")
  message(FATAL_ERROR "second mpirun study did not reuse the cache (${rc}): ${out} ${err}")
endif()
