# Command-line tests of `gsa compare` (ctest names gsa.cli.compare.*). Included by
# tests/CMakeLists.txt after cli_tests.cmake and forming_cli_tests.cmake (it uses their
# sf_gsa_cli_test and sf_forming_cli_test).
#
#  - bad inputs: a missing folder (exit 1), mismatched fibre modes (exit 1), a bad option (2);
#  - gsa.cli.compare.self: a grid against itself, zero differences;
#  - gsa.cli.compare.simform: simform run --grid-out -> gsa analyse -> gsa compare of the
#    analysis against the grid file (end to end, one pipeline);
#  - gsa.cli.compare.worked_example (label long): the worked example of data/compare/README.md,
#    checked to pick the right stiffness.

if(NOT COMMAND sf_gsa_cli_test)
  return()
endif()
set(sf_cmp ${PROJECT_BINARY_DIR}/cli/compare)

sf_gsa_cli_test(compare.missing_folder
  COMMAND compare ${sf_cmp}/no_such_folder data/gsa/dome/grid.csv --out ${sf_cmp}/never --no-plots
  EXIT 1 STDERR "no_such_folder: no such folder or file" ABSENT ${sf_cmp}/never)
sf_gsa_cli_test(compare.bad_register
  COMMAND compare data/gsa/dome/grid.csv data/gsa/dome/grid.csv --out ${sf_cmp}/never --register nearest
  EXIT 2 STDERR "--register: expected auto, ids, surface or none, found 'nearest'")
sf_gsa_cli_test(compare.setup_trellis_fibres
  COMMAND analyse data/gsa/trellis/grid.csv --fibres 0,90 --no-plots --out ${sf_cmp}/trellis_fibres
  FIXTURES_SETUP gsa_compare_trellis_fibres)
sf_gsa_cli_test(compare.setup_trellis_plain
  COMMAND analyse data/gsa/trellis/grid.csv --no-plots --out ${sf_cmp}/trellis_plain
  FIXTURES_SETUP gsa_compare_trellis_plain)
sf_gsa_cli_test(compare.fibre_mismatch
  COMMAND compare ${sf_cmp}/trellis_fibres ${sf_cmp}/trellis_plain --out ${sf_cmp}/never --no-plots
  EXIT 1 STDERR "mismatched fibre modes: .*trellis_fibres was analysed in fibre mode \\(0,90 deg\\)"
  FIXTURES_REQUIRED gsa_compare_trellis_fibres gsa_compare_trellis_plain)
sf_gsa_cli_test(compare.self
  COMMAND compare data/gsa/dome/grid.csv data/gsa/dome/grid.csv --out ${sf_cmp}/self
  STDERR "441 of 441 measured marks compared. registration by shared marks \\(ids\\): rotation 0 deg, RMS distance 0 mm"
  EXISTS ${sf_cmp}/self/differences.csv|${sf_cmp}/self/summary.json|${sf_cmp}/self/report.html|${sf_cmp}/self/diff_major.png|${sf_cmp}/self/compare.vtp)
# Two analyses and nine pictures: more than the default minute on a loaded machine.
set_tests_properties(gsa.cli.compare.self PROPERTIES TIMEOUT 300)

if(NOT COMMAND sf_forming_cli_test)
  return()
endif()
# End to end: a simform sample with --grid-out, its gsa analysis, and the comparison of the
# two (the grid file is analysed again inside gsa compare with the same settings).
sf_forming_cli_test(compare_setup_grid
  COMMAND run data/forming/uniaxial_0.yaml --out ${sf_cmp}/uniaxial_0 --grid-out ${sf_cmp}/uniaxial_0/grid.csv
  EXISTS ${sf_cmp}/uniaxial_0/grid.csv FIXTURES_SETUP gsa_compare_simform_grid)
sf_gsa_cli_test(compare.setup_simform_analysis
  COMMAND analyse ${sf_cmp}/uniaxial_0/grid.csv --no-plots --out ${sf_cmp}/uniaxial_0/gsa
  FIXTURES_REQUIRED gsa_compare_simform_grid FIXTURES_SETUP gsa_compare_simform_analysis)
sf_gsa_cli_test(compare.simform
  COMMAND compare ${sf_cmp}/uniaxial_0/gsa ${sf_cmp}/uniaxial_0/grid.csv --out ${sf_cmp}/uniaxial_0/cmp --no-plots
  STDERR "441 of 441 measured marks compared. registration by shared marks \\(ids\\): rotation 0 deg, RMS distance 0 mm. major strain difference mean 0, RMS 0"
  FIXTURES_REQUIRED gsa_compare_simform_grid gsa_compare_simform_analysis)

# The worked example (data/compare/README.md): two stiffnesses against the "measurement".
add_test(NAME gsa.cli.compare.worked_example
         COMMAND ${CMAKE_COMMAND} -DSIMFORM=$<TARGET_FILE:simform> -DGSA=$<TARGET_FILE:gsa> -DOUT=${sf_cmp}/worked
                 -P ${CMAKE_CURRENT_LIST_DIR}/cli/compare_worked_example.cmake
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(gsa.cli.compare.worked_example PROPERTIES LABELS "gsa;cli;long" TIMEOUT 900)
