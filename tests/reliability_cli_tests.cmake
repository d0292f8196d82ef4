# Issue 20, "every bad input named": command-line reproducers of the bad inputs and
# options the issue lists (ctest names gsa.cli.bad.* and forming.cli.bad.*). Each failed
# before (wrong exit code, "internal error", or exit 0 with a silently wrong result).
# Included by tests/CMakeLists.txt after cli_tests.cmake and forming_cli_tests.cmake.
if(NOT COMMAND sf_gsa_cli_test)
  return()
endif()

set(SF_BAD_DIR ${PROJECT_BINARY_DIR}/cli/bad)
file(MAKE_DIRECTORY ${SF_BAD_DIR})
set(grid data/gsa/dome/grid.csv)
set(out ${SF_BAD_DIR}/out)

# Options: NaN and infinities name the option (exit 2); before, --beta nan was ignored and
# inf failed later in the fit without naming it.
sf_gsa_cli_test(bad.beta_nan COMMAND analyse ${grid} --out ${out}/beta_nan --no-plots --beta nan EXIT 2 STDERR "--beta")
sf_gsa_cli_test(bad.gamma_inf COMMAND analyse ${grid} --out ${out}/gamma_inf --no-plots --gamma inf EXIT 2 STDERR "--gamma")
sf_gsa_cli_test(bad.smoothing_scale_inf COMMAND analyse ${grid} --out ${out}/smoothing_scale_inf --no-plots --smoothing-scale inf
                EXIT 2 STDERR "--smoothing-scale")
sf_gsa_cli_test(bad.fibres_nan COMMAND analyse ${grid} --out ${out}/fibres_nan --no-plots --fibres nan,90 EXIT 2 STDERR "--fibres")
sf_gsa_cli_test(bad.units_newline COMMAND analyse ${grid} --out ${out}/units_newline --no-plots --units "mm\nx" EXIT 2
                STDERR "--units")
sf_gsa_cli_test(bad.delimiter_hash COMMAND analyse ${grid} --out ${out}/delimiter_hash --no-plots --delimiter "#" EXIT 2
                STDERR "--delimiter" STDERR_NOT "internal error")
sf_gsa_cli_test(bad.delimiter_quote COMMAND analyse ${grid} --out ${out}/delimiter_quote --no-plots --delimiter "\"" EXIT 2
                STDERR "--delimiter" STDERR_NOT "internal error")
# An empty argument cannot pass through a CMake list: through sh.
add_test(NAME gsa.cli.bad.out_empty
         COMMAND sh -c "'$<TARGET_FILE:gsa>' analyse ${grid} --no-plots --out '' 2>&1; echo exit=$?"
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(gsa.cli.bad.out_empty PROPERTIES LABELS "gsa;cli" TIMEOUT 60
                     PASS_REGULAR_EXPRESSION "--out: empty.*exit=2")

# Mesh files: a folder and a number beyond a double were "internal error, please report".
sf_gsa_cli_test(bad.mesh_folder COMMAND analyse ${grid} --out ${out}/mesh_folder --no-plots --mesh data/gsa EXIT 1
                STDERR "data/gsa: is a folder" STDERR_NOT "internal error")
file(WRITE ${SF_BAD_DIR}/mesh_1e400.json
     "{\"nodes\": [[-50,-50,0],[50,-50,0],[-50,50,1e400],[50,50,0]], \"elements\": [[0,1,2,3]]}\n")
sf_gsa_cli_test(bad.mesh_number_overflow COMMAND analyse ${grid} --out ${out}/mesh_number_overflow --no-plots
                --mesh ${SF_BAD_DIR}/mesh_1e400.json EXIT 1 STDERR "mesh_1e400.json.*1e400" STDERR_NOT "internal error")
# A user mesh that covers a small part of the marks: a warning with the count.
file(WRITE ${SF_BAD_DIR}/mesh_small.json
     "{\"nodes\": [[-6,-6,0],[6,-6,0],[-6,6,0],[6,6,0]], \"elements\": [[0,1,2,3]]}\n")
sf_gsa_cli_test(bad.mesh_not_covering COMMAND analyse ${grid} --out ${out}_small --no-plots
                --mesh ${SF_BAD_DIR}/mesh_small.json STDERR "marks lie more than half a mark spacing off")

# --method triangles with marks that form no triangle: exit 1, no results folder.
file(WRITE ${SF_BAD_DIR}/no_triangles.csv
     "id,X,Y,Z,x,y,z,i,j\na,0,0,0,0,0,0,0,0\nb,10,0,0,10.1,0,0,2,0\nc,0,10,0,0,10.1,0,0,2\nd,10,10,0,10.1,10.1,0,2,2\n")
sf_gsa_cli_test(bad.triangles_nothing COMMAND analyse ${SF_BAD_DIR}/no_triangles.csv --method triangles
                --out ${SF_BAD_DIR}/no_triangles_out --no-plots EXIT 1 STDERR "no mark could be analysed"
                REMOVE ${SF_BAD_DIR}/no_triangles_out ABSENT ${SF_BAD_DIR}/no_triangles_out)

# A 2 MB header line is not echoed whole.
string(REPEAT "a" 2000000 long_header)
file(WRITE ${SF_BAD_DIR}/long_header.csv "id,${long_header},x\n1,2,3\n")
sf_gsa_cli_test(bad.long_header COMMAND analyse ${SF_BAD_DIR}/long_header.csv --out ${out}/long_header --no-plots EXIT 1
                STDERR "characters left out")

# simform case files.
if(COMMAND sf_forming_cli_test)
  file(WRITE ${SF_BAD_DIR}/no_materials.yaml
       "plies:\n  - name: p\n    size: [10, 10]\n    thickness: 1\n    elements: [2, 2]\n    material: m\n"
       "boundary_conditions:\n  - clamp: {ply: p, edge: x0}\nsolver: {steps: 2, bogus: 1}\n")
  sf_forming_cli_test(bad.missing_materials COMMAND check ${SF_BAD_DIR}/no_materials.yaml EXIT 1
                      STDERR "missing required key 'materials'.*bogus")
  file(WRITE ${SF_BAD_DIR}/end_time.yaml
       "materials:\n  m: {neo_hookean: {E: 1000, nu: 0.3}, density: 1e-9}\n"
       "plies:\n  - name: p\n    size: [10, 10]\n    thickness: 1\n    elements: [2, 2]\n    material: m\n"
       "boundary_conditions:\n  - clamp: {ply: p, edge: x0}\nsolver: {analysis: dynamic, end_time: 1e300, steps: 2}\n")
  sf_forming_cli_test(bad.end_time COMMAND check ${SF_BAD_DIR}/end_time.yaml EXIT 1 STDERR "end_time: 1e300 s is beyond")
endif()
