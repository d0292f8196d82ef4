# The worked example of data/compare/README.md, as written there: simulate the inflation
# with E = 1.0 and E = 1.3 MPa, compare each with data/compare/measured.csv (made from the
# E = 1.0 run with noise, missing marks, blunders and a rigid misplacement), and check that
# E = 1.0 wins on every difference statistic and that the misplacement is recovered.
#
#   cmake -DSIMFORM=... -DGSA=... -DOUT=DIR -P compare_worked_example.cmake
foreach(v SIMFORM GSA OUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "compare_worked_example.cmake: -D${v}= missing")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
foreach(E 1.0 1.3)
  execute_process(COMMAND ${SIMFORM} -q run data/compare/inflation_E${E}.yaml --out ${OUT}/E${E}
                          --grid-out ${OUT}/E${E}/grid.csv RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "simform run E = ${E} failed (${rc}): ${err}")
  endif()
  execute_process(COMMAND ${GSA} compare data/compare/measured.csv ${OUT}/E${E}/grid.csv --out ${OUT}/compare_E${E}
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  message(STATUS "E = ${E}: ${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "gsa compare E = ${E} failed (${rc}): ${err}")
  endif()
  file(READ ${OUT}/compare_E${E}/summary.json j)
  foreach(f major minor thickness_change_pct shape_deviation)
    string(JSON rms_${f}_${E} GET "${j}" statistics ${f} rms)
  endforeach()
  string(JSON angle_${E} GET "${j}" registration rotation_deg)
  string(JSON matched_${E} GET "${j}" counts matched)
endforeach()
foreach(f major minor thickness_change_pct shape_deviation)
  message(STATUS "RMS ${f} difference: E = 1.0: ${rms_${f}_1.0}, E = 1.3: ${rms_${f}_1.3}")
  if(NOT rms_${f}_1.0 LESS rms_${f}_1.3)
    message(FATAL_ERROR "E = 1.0 should win on ${f}: ${rms_${f}_1.0} vs ${rms_${f}_1.3}")
  endif()
endforeach()
# The measurement was misplaced by 4 deg; the noise moves the recovered angle by far less than 0.05 deg.
if(angle_1.0 LESS 3.95 OR angle_1.0 GREATER 4.05)
  message(FATAL_ERROR "registration angle ${angle_1.0} deg, expected 4 deg")
endif()
if(NOT matched_1.0 EQUAL 419)
  message(FATAL_ERROR "expected 419 matched marks (441 less 22 not digitised), found ${matched_1.0}")
endif()
