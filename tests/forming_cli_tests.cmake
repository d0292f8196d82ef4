# Command-line tests of simform (ctest names forming.cli.*, so `ctest -R '^forming\.'`
# runs them with the unit tests). Included by tests/CMakeLists.txt.
#
#  - forming.cli.check.<case> / forming.cli.run.<case>: `simform check` and
#    `simform run` on every sample case in data/forming/ (the command lines of
#    docs/forming.md);
#  - forming.cli.<name>: exit codes 1 (bad case, no convergence) and 2 (usage);
#  - forming.cli.grid_roundtrip: simform run --grid-out -> gsa analyse, checked by
#    tests/forming/grid_roundtrip.sh;
#  - forming.cli.docs_grid: writes the grid file that docs/forming.md's
#    `build/bin/gsa analyse results/uniaxial_0/grid.csv ...` line reads (that line is
#    registered by cli_tests.cmake, which requires the fixture named below).
#
# Exit codes and output checks go through tests/cli/check_exit.cmake.

if(NOT TARGET simform)
  return()
endif()
if(TARGET forming_tests)
  add_dependencies(forming_tests simform)
endif()

set(SF_FORMING_CLI_DIR ${PROJECT_BINARY_DIR}/cli/forming)
set(SF_FORMING_CHECK_EXIT ${CMAKE_CURRENT_LIST_DIR}/cli/check_exit.cmake)
file(MAKE_DIRECTORY ${SF_FORMING_CLI_DIR})

# sf_forming_cli_test(NAME COMMAND args... [EXIT n] [STDERR re] [STDOUT re] [REMOVE path]
#                     [EXISTS p1|p2] [ABSENT p1|p2] [FIXTURES_SETUP f] [TIMEOUT s])
# COMMAND args follow `simform`; runs from the repository root.
function(sf_forming_cli_test name)
  cmake_parse_arguments(A "" "EXIT;STDERR;STDOUT;REMOVE;EXISTS;ABSENT;FIXTURES_SETUP;TIMEOUT" "COMMAND" ${ARGN})
  if(A_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "sf_forming_cli_test(${name}): unknown arguments ${A_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT DEFINED A_EXIT)
    set(A_EXIT 0)
  endif()
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 120)
  endif()
  set(defs -DEXPECT_EXIT=${A_EXIT})
  foreach(pair STDERR:STDERR_REGEX STDOUT:STDOUT_REGEX REMOVE:REMOVE EXISTS:EXPECT_EXISTS ABSENT:EXPECT_ABSENT)
    string(REPLACE ":" ";" kv ${pair})
    list(GET kv 0 key)
    list(GET kv 1 var)
    if(DEFINED A_${key})
      list(APPEND defs "-D${var}=${A_${key}}")
    endif()
  endforeach()
  add_test(NAME forming.cli.${name}
           COMMAND ${CMAKE_COMMAND} ${defs} -P ${SF_FORMING_CHECK_EXIT} -- $<TARGET_FILE:simform> ${A_COMMAND}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(forming.cli.${name} PROPERTIES LABELS "forming;cli" TIMEOUT ${A_TIMEOUT})
  if(A_FIXTURES_SETUP)
    set_tests_properties(forming.cli.${name} PROPERTIES FIXTURES_SETUP ${A_FIXTURES_SETUP})
  endif()
endfunction()

# ---------------------------------------------------------------- samples in data/forming

file(GLOB sf_forming_cases CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/data/forming/*.yaml)
foreach(case_file IN LISTS sf_forming_cases)
  get_filename_component(case ${case_file} NAME_WE)
  sf_forming_cli_test(check.${case}
    COMMAND check data/forming/${case}.yaml
    STDOUT "${case}\\.yaml: ok")
  set(out ${SF_FORMING_CLI_DIR}/${case})
  sf_forming_cli_test(run.${case}
    COMMAND run data/forming/${case}.yaml --out ${out}
    REMOVE ${out}
    STDERR "converged: "
    EXISTS "${out}/result.pvd|${out}/history.csv|${out}/summary.json|${out}/steps/step_0000.vtu")
endforeach()

# ---------------------------------------------------------------- exit codes

# Bad case: every problem listed with file:line:column, exit 1, no output folder.
file(WRITE ${SF_FORMING_CLI_DIR}/broken.yaml
"materials:
  gfpp:
    transversely_isotropic: {E_f: 25000, E_T: -1, G_L: 0.5, G_T: 0.4}
plies:
  - {name: a, size: [100, 20], thickness: thick, elements: [4, 2], material: gfpp}
boundary_conditions:
  - clamp: {ply: a, edge: x2}
solvr: {steps: 3}
")
sf_forming_cli_test(check_broken
  COMMAND check ${SF_FORMING_CLI_DIR}/broken.yaml
  EXIT 1
  STDERR "broken\\.yaml:3:[0-9]+: .*E_T.*broken\\.yaml:5:[0-9]+: .*thick.*broken\\.yaml:7:[0-9]+: .*x2.*broken\\.yaml:8:1: .*solvr.*simform: 4 problems")
sf_forming_cli_test(run_broken
  COMMAND run ${SF_FORMING_CLI_DIR}/broken.yaml --out ${SF_FORMING_CLI_DIR}/broken_out
  EXIT 1
  STDERR "broken\\.yaml:3:[0-9]+: .*3 more problems"
  ABSENT ${SF_FORMING_CLI_DIR}/broken_out)
sf_forming_cli_test(run_missing_case
  COMMAND run ${SF_FORMING_CLI_DIR}/no_such.yaml --out ${SF_FORMING_CLI_DIR}/missing_out
  EXIT 1 STDERR "no_such\\.yaml" ABSENT ${SF_FORMING_CLI_DIR}/missing_out)

# A run that cannot converge: exit 1 naming the step; a partial result marked as such.
file(READ ${PROJECT_SOURCE_DIR}/data/forming/uniaxial_0.yaml sf_uniaxial)
string(REGEX REPLACE "solver:[^\n]*" "solver: {steps: 4, max_iterations: 1, min_increment: 1}" sf_uniaxial "${sf_uniaxial}")
file(WRITE ${SF_FORMING_CLI_DIR}/stuck.yaml "${sf_uniaxial}")
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/data/forming/uniaxial_0.yaml)
sf_forming_cli_test(run_not_converged
  COMMAND run ${SF_FORMING_CLI_DIR}/stuck.yaml --out ${SF_FORMING_CLI_DIR}/stuck_out
  REMOVE ${SF_FORMING_CLI_DIR}/stuck_out
  EXIT 1
  STDERR "step 1 of 4 .*did not converge.*not_converged"
  EXISTS "${SF_FORMING_CLI_DIR}/stuck_out/summary.json|${SF_FORMING_CLI_DIR}/stuck_out/history.csv")

# Wrong usage: exit 2.
sf_forming_cli_test(run_no_out COMMAND run data/forming/uniaxial_0.yaml EXIT 2 STDERR "--out")
sf_forming_cli_test(run_bad_grid_marks
  COMMAND run data/forming/uniaxial_0.yaml --out ${SF_FORMING_CLI_DIR}/bad_marks --grid-marks 1
  EXIT 2 STDERR "--grid-marks" ABSENT ${SF_FORMING_CLI_DIR}/bad_marks)
sf_forming_cli_test(check_no_case COMMAND check EXIT 2)

# ---------------------------------------------------------------- simform -> gsa

if(TARGET gsa)
  add_test(NAME forming.cli.grid_roundtrip
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/forming/grid_roundtrip.sh $<TARGET_FILE:simform> $<TARGET_FILE:gsa>
                   ${PROJECT_SOURCE_DIR} ${SF_FORMING_CLI_DIR}/grid_roundtrip)
  set_tests_properties(forming.cli.grid_roundtrip PROPERTIES LABELS "forming;cli" TIMEOUT 120
                       PASS_REGULAR_EXPRESSION "grid round trip ok")

  # The grid file read by docs/forming.md's gsa line (cli_tests.cmake maps results/ to
  # build/cli/docs/docs_forming/results/ and requires this fixture for that input).
  set(sf_docs_results ${PROJECT_BINARY_DIR}/cli/docs/docs_forming/results)
  sf_forming_cli_test(docs_grid
    COMMAND run data/forming/uniaxial_0.yaml --out ${sf_docs_results}/uniaxial_0
            --grid-out ${sf_docs_results}/uniaxial_0/grid.csv
    EXISTS ${sf_docs_results}/uniaxial_0/grid.csv
    FIXTURES_SETUP gsa_docs_docs_forming_uniaxial_0_grid_csv)
endif()

# ---------------------------------------------------------------- simform stability

include(${CMAKE_CURRENT_LIST_DIR}/forming/stability_cli.cmake)

# Forming results and pictures (issue 13 items 3-4; docs/forming.md "Forming results",
# "Pictures and report"): a 2-D bend run draws its pictures by default, `simform plot`
# draws them again, --no-plots skips them, bad input is named.
set(sf_plot_out ${SF_FORMING_CLI_DIR}/plot_bend)
sf_forming_cli_test(plot.run_bend
  COMMAND run tests/forming/cases/bend_2d.yaml --out ${sf_plot_out}
  REMOVE ${sf_plot_out}
  STDERR "converged: .*wrote [0-9]+ pictures"
  EXISTS "${sf_plot_out}/report.html|${sf_plot_out}/plots/section.png|${sf_plot_out}/plots/fibres.png|${sf_plot_out}/plots/shear_angle.png|${sf_plot_out}/plots/thickness.png|${sf_plot_out}/plots/force_displacement.png|${sf_plot_out}/plots/frames/frame_0000.png|${sf_plot_out}/tool_force.csv|${sf_plot_out}/profiles.csv"
  FIXTURES_SETUP sf_plot_bend)
sf_forming_cli_test(plot.again
  COMMAND plot ${sf_plot_out} --frames 2 --no-animation --size 800x600
  STDERR "wrote 8 pictures"
  EXISTS "${sf_plot_out}/plots/frames/frame_0001.png")
set_tests_properties(forming.cli.plot.again PROPERTIES FIXTURES_REQUIRED sf_plot_bend)
sf_forming_cli_test(plot.bad_ply
  COMMAND plot ${sf_plot_out} --ply nope EXIT 2 STDERR "--ply: no ply 'nope'.*lam\\.1, lam\\.2")
set_tests_properties(forming.cli.plot.bad_ply PROPERTIES FIXTURES_REQUIRED sf_plot_bend)
sf_forming_cli_test(plot.not_results
  COMMAND plot ${SF_FORMING_CLI_DIR}/no_such_results EXIT 1 STDERR "no_such_results: not a folder")
sf_forming_cli_test(plot.bad_size
  COMMAND plot ${sf_plot_out} --size 10x10 EXIT 2 STDERR "--size")
set(sf_noplot_out ${SF_FORMING_CLI_DIR}/plot_none)
sf_forming_cli_test(plot.run_no_plots
  COMMAND run data/forming/uniaxial_0.yaml --out ${sf_noplot_out} --no-plots
  REMOVE ${sf_noplot_out}
  EXISTS "${sf_noplot_out}/summary.json|${sf_noplot_out}/tool_force.csv"
  ABSENT "${sf_noplot_out}/report.html|${sf_noplot_out}/plots")
# The section of a 3-D part (issue 13 item 4): a small quarter dome, its section along
# the diagonal; a section angle out of range is named.
set(sf_section_out ${SF_FORMING_CLI_DIR}/plot_dome_3d)
sf_forming_cli_test(plot.run_dome_3d
  COMMAND run tests/forming/cases/dome_3d.yaml --out ${sf_section_out} --no-plots
  REMOVE ${sf_section_out}
  EXISTS "${sf_section_out}/summary.json"
  FIXTURES_SETUP sf_plot_dome_3d)
sf_forming_cli_test(plot.section_3d
  COMMAND plot ${sf_section_out} --section 45 --frames 0 --no-animation --size 800x600
  STDERR "wrote 8 pictures"
  EXISTS "${sf_section_out}/plots/section.png")
set_tests_properties(forming.cli.plot.section_3d PROPERTIES FIXTURES_REQUIRED sf_plot_dome_3d)
sf_forming_cli_test(plot.bad_section
  COMMAND plot ${sf_section_out} --section 400 EXIT 2 STDERR "--section")
set_tests_properties(forming.cli.plot.bad_section PROPERTIES FIXTURES_REQUIRED sf_plot_dome_3d)
