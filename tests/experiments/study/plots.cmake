# The study plots are made from kerf's own files: run the fracture model on potato_rect_cut, plot
# its force profile, a Pareto chart of a small table and a stability map of two small stability
# tables, and check that each PNG and PDF exists and is one (magic bytes).
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
# A stability map of two models from stability tables in `kerf stability`'s CSV form.
file(WRITE ${WORK}/stab_a.csv "axis,value,outcome,peak force [N],expected scale [N],reversing increments [%],note\n"
           "rate,0.25,oscillating,3,2,40,\nrate,4,bounded,2,2,0,\nstiffness,1000,diverged,900,2,1,\npoisson,0.499,refused,,2,,\"no\"\n")
file(WRITE ${WORK}/stab_b.csv "axis,value,outcome,peak force [N],expected scale [N],reversing increments [%],note\n"
           "rate,0.25,bounded,2,2,0,\nstiffness,1000,NaN,0,2,0,\n")
execute_process(COMMAND /usr/bin/python3 ${PLOT} stability ${WORK}/stability a=${WORK}/stab_a.csv b=${WORK}/stab_b.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "plot_study.py stability failed: ${err}")
endif()
foreach(stem profiles pareto stability)
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
