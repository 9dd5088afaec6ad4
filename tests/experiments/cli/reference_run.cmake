# kerf reference as a user runs it: clay_pull at 6 evenly spaced samples (adaptive sampling off, so
# that the count is known; ReferenceRun.AdaptiveSampling* tests it) and the end of the pull at
# t = 1.6 s, a vertex of the motion the load path passes through (7 samples), writes the profile,
# the manifest and the ParaView collection with one .vtu per sample. Linear tetrahedra (--degree 1): the files
# are this test's subject, and the scene's own quadratic ones take minutes (the study's levels and
# SolverVersion check them).
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${KERF} reference clay_pull --degree 1 --samples 6 --adaptive 0 -o ${WORK}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kerf reference clay_pull failed (${rc}):\n${out}\n${err}")
endif()
foreach(f profile.csv manifest.json fields.pvd fields/step_0000.vtu fields/step_0006.vtu)
  if(NOT EXISTS ${WORK}/${f})
    message(FATAL_ERROR "kerf reference did not write ${f}")
  endif()
endforeach()
file(STRINGS ${WORK}/profile.csv lines)
list(LENGTH lines n)
if(NOT n EQUAL 8)
  message(FATAL_ERROR "profile.csv has ${n} lines, expected a header and 7 rows")
endif()
list(GET lines 0 header)
if(NOT header STREQUAL "t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s")
  message(FATAL_ERROR "profile header: ${header}")
endif()
file(READ ${WORK}/manifest.json manifest)
foreach(key sha256 git_commit dofs linear_solver newton_iterations_total "tool_coupling\": \"tied")
  if(NOT manifest MATCHES "${key}")
    message(FATAL_ERROR "manifest lacks ${key}")
  endif()
endforeach()
if(NOT err MATCHES "sample 7/7" OR NOT err MATCHES "ETA")
  message(FATAL_ERROR "no progress lines on stderr:\n${err}")
endif()
