# The study plots are made from kerf's own files: run the fracture model on potato_rect_cut, plot
# its force profile and a Pareto chart of a small table, and check that each PNG and PDF exists
# and is one (magic bytes).
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${KERF} run potato_rect_cut --model fracture -o ${WORK}/run RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kerf run failed")
endif()
execute_process(COMMAND /usr/bin/python3 ${PLOT} profiles ${WORK}/profiles fracture=${WORK}/run/profile.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "plot_study.py profiles failed: ${err}")
endif()
file(WRITE ${WORK}/table.csv "model,RMS error [%],p99 cost [µs]\nfracture,12.5,6.4\nslow,1.5,2500\n")
execute_process(COMMAND /usr/bin/python3 ${PLOT} pareto ${WORK}/pareto ${WORK}/table.csv
                        --error "RMS error [%]" --cost "p99 cost [µs]" --label model
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "plot_study.py pareto failed: ${err}")
endif()
foreach(stem profiles pareto)
  file(READ ${WORK}/${stem}.png png LIMIT 4 HEX)
  file(READ ${WORK}/${stem}.pdf pdf LIMIT 4 HEX)
  if(NOT png STREQUAL "89504e47" OR NOT pdf STREQUAL "25504446") # "\x89PNG", "%PDF"
    message(FATAL_ERROR "${stem}: not a PNG (${png}) or not a PDF (${pdf})")
  endif()
endforeach()
file(GLOB leftovers ${WORK}/*.tmp.*)
if(leftovers)
  message(FATAL_ERROR "temporary files left: ${leftovers}")
endif()
