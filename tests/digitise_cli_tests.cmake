# Command-line tests of gsa calibrate / digitise / synth-images (docs/digitise.md), and the
# long digitising studies. Included by tests/CMakeLists.txt after cli_tests.cmake (which
# defines sf_gsa_cli_test). ctest names gsa.cli.digitise_*, so `ctest -R '^gsa\.'` runs them.

if(NOT TARGET gsa OR NOT COMMAND sf_gsa_cli_test)
  return()
endif()

set(SF_DIG_DIR ${PROJECT_BINARY_DIR}/cli/digitise)

# Images: a small synthetic study (800 x 600, 5 chessboard views per camera) and a smaller
# one for the size-mismatch checks.
sf_gsa_cli_test(digitise_synth_images
  COMMAND synth-images --out ${SF_DIG_DIR}/study --size 800x600 --views 5 --occlusion
  REMOVE ${SF_DIG_DIR}/study
  MAKE_DIRECTORY ${SF_DIG_DIR}
  EXISTS "${SF_DIG_DIR}/study/calib/cam1/view_04.png|${SF_DIG_DIR}/study/formed/cam1.png|${SF_DIG_DIR}/study/truth.csv|${SF_DIG_DIR}/study/rig_true.json"
  FIXTURES_SETUP gsa_dig_study)
sf_gsa_cli_test(digitise_synth_images_small
  COMMAND synth-images --out ${SF_DIG_DIR}/small --size 400x300 --views 3
  REMOVE ${SF_DIG_DIR}/small
  MAKE_DIRECTORY ${SF_DIG_DIR}
  FIXTURES_SETUP gsa_dig_small)

# calibrate -> digitise (flat blank and formed part) -> analyse.
sf_gsa_cli_test(digitise_calibrate
  COMMAND calibrate ${SF_DIG_DIR}/study/calib/cam0 ${SF_DIG_DIR}/study/calib/cam1 --pattern 11x8 --spacing 12
          -o ${SF_DIG_DIR}/rig.json
  REMOVE ${SF_DIG_DIR}/rig.json
  STDERR "cam1 relative to cam0: 5 image pairs.*wrote"
  EXISTS ${SF_DIG_DIR}/rig.json
  FIXTURES_REQUIRED gsa_dig_study
  FIXTURES_SETUP gsa_dig_rig)
sf_gsa_cli_test(digitise_two_states
  COMMAND digitise -c ${SF_DIG_DIR}/rig.json
          --undeformed ${SF_DIG_DIR}/study/flat/cam0.png ${SF_DIG_DIR}/study/flat/cam1.png
          --deformed ${SF_DIG_DIR}/study/formed/cam0.png ${SF_DIG_DIR}/study/formed/cam1.png
          -o ${SF_DIG_DIR}/grid.csv --report ${SF_DIG_DIR}/report.json
  REMOVE ${SF_DIG_DIR}/grid.csv
  STDERR "reference mark at.*deformed: [0-9]+ marks triangulated.*wrote .*grid.csv: [0-9]+ marks"
  EXISTS "${SF_DIG_DIR}/grid.csv|${SF_DIG_DIR}/report.json"
  FIXTURES_REQUIRED gsa_dig_rig
  FIXTURES_SETUP gsa_dig_grid)
sf_gsa_cli_test(digitise_analyse
  COMMAND analyse ${SF_DIG_DIR}/grid.csv --out ${SF_DIG_DIR}/strains --no-plots
  REMOVE ${SF_DIG_DIR}/strains
  STDERR "points analysed"
  EXISTS ${SF_DIG_DIR}/strains/strains.csv
  FIXTURES_REQUIRED gsa_dig_grid)
# digitise ... -o - | gsa analyse - : the grid through a pipe, undeformed from the pitch.
add_test(NAME gsa.cli.digitise_pipe_to_analyse
  COMMAND sh -c "set -e; rm -rf '${SF_DIG_DIR}/piped'; '$<TARGET_FILE:gsa>' -q digitise -c '${SF_DIG_DIR}/rig.json' --pitch 5 --deformed '${SF_DIG_DIR}/study/formed/cam0.png' '${SF_DIG_DIR}/study/formed/cam1.png' -o - | '$<TARGET_FILE:gsa>' analyse - --out '${SF_DIG_DIR}/piped' --no-plots; test -s '${SF_DIG_DIR}/piped/strains.csv'")
set_tests_properties(gsa.cli.digitise_pipe_to_analyse PROPERTIES LABELS "gsa;cli" TIMEOUT 120
  FIXTURES_REQUIRED gsa_dig_rig PASS_REGULAR_EXPRESSION "points analysed; results in")

# Bad input: exit 1 with the file named; wrong usage: exit 2.
sf_gsa_cli_test(digitise_missing_image
  COMMAND digitise -c ${SF_DIG_DIR}/rig.json --pitch 5 --deformed ${SF_DIG_DIR}/study/formed/cam0.png
          ${SF_DIG_DIR}/study/formed/nothing.png -o ${SF_DIG_DIR}/x.csv
  EXIT 1 STDERR "nothing\\.png: cannot read image \\(no such file\\)" ABSENT ${SF_DIG_DIR}/x.csv
  FIXTURES_REQUIRED gsa_dig_rig)
sf_gsa_cli_test(digitise_image_of_another_size
  COMMAND digitise -c ${SF_DIG_DIR}/rig.json --pitch 5 --deformed ${SF_DIG_DIR}/study/formed/cam0.png
          ${SF_DIG_DIR}/small/formed/cam1.png -o ${SF_DIG_DIR}/x.csv
  EXIT 1 STDERR "small/formed/cam1\\.png: 400 x 300 pixels, but camera cam1 .* 800 x 600" ABSENT ${SF_DIG_DIR}/x.csv
  FIXTURES_REQUIRED "gsa_dig_rig;gsa_dig_small")
sf_gsa_cli_test(digitise_one_image_too_few
  COMMAND digitise -c ${SF_DIG_DIR}/rig.json --pitch 5 --deformed ${SF_DIG_DIR}/study/formed/cam0.png
          -o ${SF_DIG_DIR}/x.csv
  EXIT 1 STDERR "--deformed: 1 image given, but the rig .* has 2 cameras" ABSENT ${SF_DIG_DIR}/x.csv
  FIXTURES_REQUIRED gsa_dig_rig)
sf_gsa_cli_test(digitise_rig_of_other_cameras
  COMMAND digitise -c ${SF_DIG_DIR}/rig.json --pitch 5
          --deformed ${SF_DIG_DIR}/study/formed/cam1.png ${SF_DIG_DIR}/study/formed/cam0.png -o ${SF_DIG_DIR}/x.csv
  EXIT 1 STDERR "cam0\\.png: .*calibration" ABSENT ${SF_DIG_DIR}/x.csv
  FIXTURES_REQUIRED gsa_dig_rig)
sf_gsa_cli_test(digitise_not_a_rig_file
  COMMAND digitise -c ${SF_DIG_DIR}/study/truth.csv --pitch 5
          --deformed ${SF_DIG_DIR}/study/formed/cam0.png ${SF_DIG_DIR}/study/formed/cam1.png -o ${SF_DIG_DIR}/x.csv
  EXIT 1 STDERR "truth\\.csv" ABSENT ${SF_DIG_DIR}/x.csv
  FIXTURES_REQUIRED gsa_dig_study)
sf_gsa_cli_test(digitise_no_grid_in_image
  COMMAND digitise -c ${SF_DIG_DIR}/rig.json --pitch 5
          --deformed ${SF_DIG_DIR}/study/calib/cam0/view_00.png ${SF_DIG_DIR}/study/calib/cam1/view_00.png
          -o ${SF_DIG_DIR}/x.csv
  EXIT 1 STDERR "view_00\\.png" STDERR_NOT "internal error" ABSENT ${SF_DIG_DIR}/x.csv
  FIXTURES_REQUIRED gsa_dig_rig)
sf_gsa_cli_test(calibrate_no_target
  COMMAND calibrate ${SF_DIG_DIR}/study/flat ${SF_DIG_DIR}/study/formed --pattern 11x8 --spacing 12
          -o ${SF_DIG_DIR}/norig.json
  EXIT 1 STDERR "camera 0: the target .* was found in 0 of 2 images.*cam0\\.png" ABSENT ${SF_DIG_DIR}/norig.json
  FIXTURES_REQUIRED gsa_dig_study)
sf_gsa_cli_test(calibrate_images_of_different_sizes
  COMMAND calibrate
          "${SF_DIG_DIR}/study/calib/cam0/view_00.png,${SF_DIG_DIR}/study/calib/cam0/view_01.png,${SF_DIG_DIR}/small/calib/cam0/view_02.png"
          --pattern 11x8 --spacing 12 -o ${SF_DIG_DIR}/norig.json
  EXIT 1 STDERR "view_02\\.png: 400 x 300 pixels, but .* is 800 x 600" ABSENT ${SF_DIG_DIR}/norig.json
  FIXTURES_REQUIRED "gsa_dig_study;gsa_dig_small")
sf_gsa_cli_test(calibrate_empty_pattern_match
  COMMAND calibrate "${SF_DIG_DIR}/study/calib/cam0/*.tif" --pattern 11x8 --spacing 12 -o ${SF_DIG_DIR}/norig.json
  EXIT 1 STDERR "no file matches" FIXTURES_REQUIRED gsa_dig_study)
sf_gsa_cli_test(digitise_both_undeformed_forms
  COMMAND digitise -c rig.json --pitch 5 --undeformed a.png b.png --deformed c.png d.png -o x.csv
  EXIT 2 STDERR "either --undeformed")
sf_gsa_cli_test(digitise_no_undeformed
  COMMAND digitise -c rig.json --deformed c.png d.png -o x.csv EXIT 2 STDERR "--pitch")
sf_gsa_cli_test(calibrate_bad_pattern
  COMMAND calibrate some/folder --pattern 11 --spacing 12 -o x.json EXIT 2 STDERR "--pattern")
sf_gsa_cli_test(synth_images_bad_shape
  COMMAND synth-images --out ${SF_DIG_DIR}/bad --shape cube EXIT 2 STDERR "--shape" ABSENT ${SF_DIG_DIR}/bad)

# Long studies at the issue's 2-megapixel size (ctest -L long; bench/gsa_digitise_bench.cpp
# prints the same figures).
set(SF_TEST_LABELS long)
sf_add_test_suite(digitise_long digitise_long sf_gsa)
unset(SF_TEST_LABELS)

# OpenCV's image codecs (with GDAL, ~120 libraries, 0.06 s) are loaded when an image is
# read or written, not at every start of gsa (gsa/digitise/image.cpp): the dynamic loader's
# list of the files it loads for `gsa --version` must not name them.
add_test(NAME gsa.cli.digitise_codecs_not_loaded_at_start
         COMMAND ${CMAKE_COMMAND} -E env LD_DEBUG=files $<TARGET_FILE:gsa> --version)
set_tests_properties(gsa.cli.digitise_codecs_not_loaded_at_start PROPERTIES
  LABELS "gsa;cli"
  PASS_REGULAR_EXPRESSION "file=libcholmod"  # the loader's list is there
  FAIL_REGULAR_EXPRESSION "libopencv_imgcodecs")
