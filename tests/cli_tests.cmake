# Command-line tests of gsa (ctest names gsa.cli.*, so `ctest -R '^gsa\.'` runs
# them with the unit tests). Included by tests/CMakeLists.txt.
#
#  - gsa.cli.<name>:          hand-written checks of the command line (exit codes
#                             0/1/2, messages, output files);
#  - gsa.cli.sample.<case>:   `gsa analyse` on every sample grid in data/gsa/ with
#                             the options in its `options` file;
#  - gsa.cli.docs.<doc>.L<n>: every `build/bin/gsa ...` line of a ```sh block in
#                             docs/**/*.md and README.md, run from the repository
#                             root as written, except that `results/...` paths go
#                             to build/cli/docs/<doc>/results/ (the source tree is
#                             never written to).
#
# Exit codes and output checks go through tests/cli/check_exit.cmake.

if(NOT TARGET gsa)
  return()
endif()

# The gsa_tests executable runs bin/gsa (tests/gsa/commands_test.cpp): build gsa with it.
if(TARGET gsa_tests)
  add_dependencies(gsa_tests gsa)
endif()

set(SF_CLI_DIR ${PROJECT_BINARY_DIR}/cli)
set(SF_CHECK_EXIT ${CMAKE_CURRENT_LIST_DIR}/cli/check_exit.cmake)

# sf_gsa_cli_test(NAME COMMAND args... [EXIT n] [STDERR re] [STDOUT re] [STDERR_NOT re]
#                 [MAKE_DIRECTORY dir] [REMOVE path] [EXISTS p1|p2] [ABSENT p1|p2]
#                 [WORKING_DIRECTORY dir] [FIXTURES_SETUP f...] [FIXTURES_REQUIRED f...]
#                 [RESOURCE_LOCK r...])
# COMMAND args follow `gsa` (the built executable is prepended).
function(sf_gsa_cli_test name)
  cmake_parse_arguments(A ""
    "EXIT;STDERR;STDOUT;STDERR_NOT;MAKE_DIRECTORY;REMOVE;EXISTS;ABSENT;WORKING_DIRECTORY"
    "COMMAND;FIXTURES_SETUP;FIXTURES_REQUIRED;RESOURCE_LOCK" ${ARGN})
  if(A_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "sf_gsa_cli_test(${name}): unknown arguments ${A_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT DEFINED A_EXIT)
    set(A_EXIT 0)
  endif()
  set(defs -DEXPECT_EXIT=${A_EXIT})
  foreach(pair STDERR:STDERR_REGEX STDOUT:STDOUT_REGEX STDERR_NOT:STDERR_NOT_REGEX
               MAKE_DIRECTORY:MAKE_DIRECTORY REMOVE:REMOVE EXISTS:EXPECT_EXISTS ABSENT:EXPECT_ABSENT)
    string(REPLACE ":" ";" kv ${pair})
    list(GET kv 0 key)
    list(GET kv 1 var)
    if(DEFINED A_${key})
      list(APPEND defs "-D${var}=${A_${key}}")
    endif()
  endforeach()
  if(NOT A_WORKING_DIRECTORY)
    set(A_WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  endif()
  add_test(NAME gsa.cli.${name}
           COMMAND ${CMAKE_COMMAND} ${defs} -P ${SF_CHECK_EXIT} -- $<TARGET_FILE:gsa> ${A_COMMAND}
           WORKING_DIRECTORY ${A_WORKING_DIRECTORY})
  set_tests_properties(gsa.cli.${name} PROPERTIES LABELS "gsa;cli" TIMEOUT 300)
  foreach(prop FIXTURES_SETUP FIXTURES_REQUIRED RESOURCE_LOCK)
    if(A_${prop})
      set_tests_properties(gsa.cli.${name} PROPERTIES ${prop} "${A_${prop}}")
    endif()
  endforeach()
endfunction()

# ---------------------------------------------------------------- hand-written

add_test(NAME gsa.cli.version COMMAND $<TARGET_FILE:gsa> --version)
string(REPLACE "." "\\." SF_VERSION_REGEX "${PROJECT_VERSION}")
set_tests_properties(gsa.cli.version PROPERTIES LABELS "gsa;cli" PASS_REGULAR_EXPRESSION "^gsa ${SF_VERSION_REGEX}")

add_test(NAME gsa.cli.info COMMAND $<TARGET_FILE:gsa> info)
set_tests_properties(gsa.cli.info PROPERTIES LABELS "gsa;cli" PASS_REGULAR_EXPRESSION "gsa ${SF_VERSION_REGEX}")

add_test(NAME gsa.cli.analyse_help COMMAND $<TARGET_FILE:gsa> analyse --help)
set_tests_properties(gsa.cli.analyse_help PROPERTIES LABELS "gsa;cli" PASS_REGULAR_EXPRESSION "--method")

add_test(NAME gsa.cli.synth_help COMMAND $<TARGET_FILE:gsa> synth --help)
set_tests_properties(gsa.cli.synth_help PROPERTIES LABELS "gsa;cli" PASS_REGULAR_EXPRESSION "--exact")

# synth -> analyse, ordered by a fixture.
sf_gsa_cli_test(synth_dome
  COMMAND synth dome --out ${SF_CLI_DIR}/dome.csv --exact ${SF_CLI_DIR}/dome_exact.csv
  MAKE_DIRECTORY ${SF_CLI_DIR}
  EXISTS "${SF_CLI_DIR}/dome.csv|${SF_CLI_DIR}/dome_exact.csv"
  FIXTURES_SETUP gsa_cli_dome)
sf_gsa_cli_test(analyse_dome
  COMMAND analyse ${SF_CLI_DIR}/dome.csv --out ${SF_CLI_DIR}/dome_out
  REMOVE ${SF_CLI_DIR}/dome_out
  STDERR "441 of 441 points analysed"
  EXISTS "${SF_CLI_DIR}/dome_out/strains.csv|${SF_CLI_DIR}/dome_out/summary.json|${SF_CLI_DIR}/dome_out/undeformed.vtp|${SF_CLI_DIR}/dome_out/deformed.vtp"
  FIXTURES_REQUIRED gsa_cli_dome
  RESOURCE_LOCK gsa_cli_dome_out)
sf_gsa_cli_test(analyse_dome_triangles
  COMMAND analyse ${SF_CLI_DIR}/dome.csv --out ${SF_CLI_DIR}/dome_triangles --method triangles
  REMOVE ${SF_CLI_DIR}/dome_triangles
  EXISTS "${SF_CLI_DIR}/dome_triangles/strains.csv|${SF_CLI_DIR}/dome_triangles/summary.json"
  FIXTURES_REQUIRED gsa_cli_dome)
sf_gsa_cli_test(analyse_quiet
  COMMAND -q analyse ${SF_CLI_DIR}/dome.csv --out ${SF_CLI_DIR}/dome_quiet
  REMOVE ${SF_CLI_DIR}/dome_quiet
  STDERR "^$"
  FIXTURES_REQUIRED gsa_cli_dome)

# Bad input: exit 1, the message names the file (and line:column), no output.
sf_gsa_cli_test(analyse_missing_file
  COMMAND analyse missing.csv --out ${SF_CLI_DIR}/missing_out
  WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
  EXIT 1
  STDERR "missing\\.csv"
  ABSENT ${SF_CLI_DIR}/missing_out)
file(WRITE ${SF_CLI_DIR}/bad_number.csv "id,X,Y,Z,x,y,z\np1,0,0,0,0,0,0\np2,1,0,0,1,abc,0\n")
sf_gsa_cli_test(analyse_bad_number
  COMMAND analyse ${SF_CLI_DIR}/bad_number.csv --out ${SF_CLI_DIR}/bad_number_out
  EXIT 1
  STDERR "bad_number\\.csv:3:6: .*'y'.*abc"
  STDERR_NOT "internal error"
  ABSENT ${SF_CLI_DIR}/bad_number_out)
file(WRITE ${SF_CLI_DIR}/collinear.csv
  "id,X,Y,Z,x,y,z\na,0,0,0,0,0,0\nb,1,1,0,1,1,0\nc,2,2,0,2,2,0\nd,3,3,0,3,3,0\ne,4,4,0,4,4,0\nf,5,5,0,5,5,0\ng,6,6,0,6,6,0\n")
sf_gsa_cli_test(analyse_collinear
  COMMAND analyse ${SF_CLI_DIR}/collinear.csv --out ${SF_CLI_DIR}/collinear_out
  EXIT 1
  STDERR "collinear\\.csv.*line"
  ABSENT ${SF_CLI_DIR}/collinear_out)

# Wrong usage: exit 2.
sf_gsa_cli_test(analyse_bogus COMMAND analyse --bogus EXIT 2)
sf_gsa_cli_test(analyse_unknown_option
  COMMAND analyse ${SF_CLI_DIR}/dome.csv --out ${SF_CLI_DIR}/bogus_out --bogus
  EXIT 2 STDERR "--bogus" ABSENT ${SF_CLI_DIR}/bogus_out
  FIXTURES_REQUIRED gsa_cli_dome)
sf_gsa_cli_test(analyse_bad_method
  COMMAND analyse ${SF_CLI_DIR}/dome.csv --out ${SF_CLI_DIR}/bad_method_out --method magic
  EXIT 2 STDERR "--method" ABSENT ${SF_CLI_DIR}/bad_method_out
  FIXTURES_REQUIRED gsa_cli_dome)
sf_gsa_cli_test(no_subcommand COMMAND EXIT 2)
sf_gsa_cli_test(synth_unknown_case COMMAND synth nosuchcase --out ${SF_CLI_DIR}/x.csv EXIT 2 STDERR "nosuchcase")

# Stage series (docs/usage.md, Stage series): a folder of GOM stage files, a stage column,
# and bad series (a missing stage file, stages of another part) with clear messages.
set(sf_series ${SF_CLI_DIR}/series)
sf_gsa_cli_test(series_gom_folder
  COMMAND analyse --stages data/formats/gom_series --no-plots --out ${sf_series}/gom
  REMOVE ${sf_series}/gom
  STDERR "stage 3/3 surface-1_10.000s: 47 of 49 points analysed \\(2 not measured in this stage\\)"
  EXISTS "${sf_series}/gom/series.pvd|${sf_series}/gom/series_strains.csv|${sf_series}/gom/stages/stage_000.vtp|${sf_series}/gom/stages/stage_002.vtp|${sf_series}/gom/strain_paths.csv|${sf_series}/gom/strains.csv|${sf_series}/gom/summary.json")
sf_gsa_cli_test(series_stage_column
  COMMAND analyse data/formats/stage_column.csv --stage-column stage --reference-stage 0 --no-plots
          --out ${sf_series}/column
  REMOVE ${sf_series}/column
  STDERR "2 stages.*stage 2/2 10: 49 of 49 points analysed"
  EXISTS "${sf_series}/column/series.pvd|${sf_series}/column/series_strains.csv")
sf_gsa_cli_test(series_missing_stage_file
  COMMAND analyse --stages data/formats/gom_series/surface-1_0.000s.csv data/formats/gom_series/nope.csv --no-plots
          --out ${sf_series}/missing
  EXIT 1
  STDERR "nope\\.csv.*no such file"
  ABSENT ${sf_series}/missing)
file(WRITE ${sf_series}/bad/s1.csv
  "id,X,Y,Z,x,y,z\na,0,0,0,0,0,0\nb,1,0,0,1.1,0,0\nc,2,0,0,2.2,0,0\nd,0,1,0,0,1,0\ne,1,1,0,1.1,1,0\nf,2,1,0,2.2,1,0\ng,0,2,0,0,2,0\nh,1,2,0,1.1,2,0\ni,2,2,0,2.2,2,0\n")
file(WRITE ${sf_series}/bad/s2.csv
  "id,X,Y,Z,x,y,z\np,0,0,0,0,0,0\nq,1,0,0,1.1,0,0\nr,2,0,0,2.2,0,0\ns,0,1,0,0,1,0\nt,1,1,0,1.1,1,0\nu,2,1,0,2.2,1,0\nv,0,2,0,0,2,0\nw,1,2,0,1.1,2,0\nx,2,2,0,2.2,2,0\n")
sf_gsa_cli_test(series_stage_of_another_part
  COMMAND analyse --stages ${sf_series}/bad/s1.csv ${sf_series}/bad/s2.csv --no-plots --out ${sf_series}/other
  EXIT 1
  STDERR "s2\\.csv: 9 of its 9 point ids are not in the first stage file"
  STDERR_NOT "internal error"
  ABSENT ${sf_series}/other)
sf_gsa_cli_test(series_stage_ids_not_in_reference
  COMMAND analyse --undeformed ${sf_series}/bad/s1.csv --stages ${sf_series}/bad/s2.csv --no-plots
          --out ${sf_series}/other_ref
  EXIT 1
  STDERR "s2\\.csv:2:1: id 'p'.*is not in the reference"
  ABSENT ${sf_series}/other_ref)
sf_gsa_cli_test(series_bad_stage_smoothing
  COMMAND analyse --stages data/formats/gom_series --stage-smoothing sometimes --no-plots --out ${sf_series}/bad_flag
  EXIT 2 STDERR "--stage-smoothing" ABSENT ${sf_series}/bad_flag)

# ---------------------------------------------------------------- samples in data/

file(GLOB sf_sample_dirs LIST_DIRECTORIES true ${PROJECT_SOURCE_DIR}/data/gsa/*)
foreach(dir IN LISTS sf_sample_dirs)
  if(NOT EXISTS ${dir}/grid.csv)
    continue()
  endif()
  get_filename_component(case ${dir} NAME)
  set(extra "")
  if(EXISTS ${dir}/options)
    file(READ ${dir}/options opts)
    string(STRIP "${opts}" opts)
    separate_arguments(extra UNIX_COMMAND "${opts}")
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${dir}/options)
  endif()
  set(out ${SF_CLI_DIR}/samples/${case})
  set(expect_stderr "points analysed")
  if(case STREQUAL "dome")
    set(expect_stderr "441 of 441 points analysed")          # docs/usage.md, Quick start
  elseif(case STREQUAL "dome_noisy")
    set(expect_stderr "425 of 441 points analysed")          # docs/usage.md, Noisy dome
  endif()
  sf_gsa_cli_test(sample.${case}
    COMMAND analyse data/gsa/${case}/grid.csv --out ${out} ${extra}
    REMOVE ${out}
    STDERR "${expect_stderr}"
    EXISTS "${out}/strains.csv|${out}/summary.json|${out}/undeformed.vtp|${out}/deformed.vtp")
endforeach()

# ---------------------------------------------------------------- command lines in docs

file(GLOB_RECURSE sf_doc_files CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/docs/*.md)
if(EXISTS ${PROJECT_SOURCE_DIR}/README.md)
  list(APPEND sf_doc_files ${PROJECT_SOURCE_DIR}/README.md)
endif()
foreach(doc IN LISTS sf_doc_files)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${doc})
  file(RELATIVE_PATH doc_rel ${PROJECT_SOURCE_DIR} ${doc})
  string(REGEX REPLACE "\\.md$" "" doc_id "${doc_rel}")
  string(REGEX REPLACE "[^A-Za-z0-9_]" "_" doc_id "${doc_id}")
  set(results ${SF_CLI_DIR}/docs/${doc_id}/results)
  # Split into lines without letting ';' or brackets in the text act on the list.
  file(READ ${doc} text)
  string(REPLACE ";" "<sf-semicolon>" text "${text}")
  string(REPLACE "[" "<sf-lbracket>" text "${text}")
  string(REPLACE "]" "<sf-rbracket>" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(in_sh FALSE)
  set(setup_paths "")  # results/ paths written by earlier setup commands of this page
  set(line_no 0)
  set(pending "")
  set(pending_line 0)
  foreach(line IN LISTS lines)
    math(EXPR line_no "${line_no} + 1")
    if(line MATCHES "^```")
      if(in_sh)
        set(in_sh FALSE)
      elseif(line MATCHES "^```(sh|bash|shell|console)[ ]*$")
        set(in_sh TRUE)
      endif()
      continue()
    endif()
    if(NOT in_sh)
      continue()
    endif()
    string(REPLACE "<sf-semicolon>" ";" line "${line}")
    string(REPLACE "<sf-lbracket>" "[" line "${line}")
    string(REPLACE "<sf-rbracket>" "]" line "${line}")
    if(pending STREQUAL "")
      set(pending_line ${line_no})
    endif()
    # Continuation lines ("... \").
    if(line MATCHES "\\\\[ ]*$")
      string(REGEX REPLACE "\\\\[ ]*$" " " line "${line}")
      string(APPEND pending "${line}")
      continue()
    endif()
    string(APPEND pending "${line}")
    set(cmd "${pending}")
    set(pending "")
    string(STRIP "${cmd}" cmd)
    string(REGEX REPLACE "^\\$ +" "" cmd "${cmd}")
    if(NOT cmd MATCHES "^build/bin/gsa( |$)")
      continue()
    endif()
    string(REGEX REPLACE "[ ]+#.*$" "" cmd "${cmd}")
    separate_arguments(tokens UNIX_COMMAND "${cmd}")
    list(REMOVE_AT tokens 0)  # build/bin/gsa
    set(args "")
    set(setup "")
    set(required "")
    set(locks "")
    set(previous "")
    list(LENGTH tokens n_tokens)
    set(writes_results FALSE)
    # Commands whose outputs later lines read: synth, and the photogrammetry chain of
    # docs/digitise.md (synth-images -> calibrate -> digitise).
    if(tokens MATCHES "(^|;)(synth|synth-images|calibrate|digitise)(;|$)")
      set(is_synth TRUE)
    else()
      set(is_synth FALSE)
    endif()
    foreach(tok IN LISTS tokens)
      if(tok MATCHES "^results/(.*)$")
        set(rel ${CMAKE_MATCH_1})
        set(mapped ${results}/${rel})
        string(REGEX REPLACE "[^A-Za-z0-9_]" "_" fixture "gsa_docs_${doc_id}_${rel}")
        if(previous MATCHES "^(--out|-o|--exact|--report)$")
          set(writes_results TRUE)
          list(APPEND locks ${fixture})
          if(is_synth)
            list(APPEND setup ${fixture})
            list(APPEND setup_paths ${rel})
          endif()
        else()
          # A file inside a folder written by an earlier setup command needs that command.
          foreach(written IN LISTS setup_paths)
            string(LENGTH "${written}/" n_written)
            string(SUBSTRING "${rel}/" 0 ${n_written} head)
            if(head STREQUAL "${written}/")
              string(REGEX REPLACE "[^A-Za-z0-9_]" "_" fixture "gsa_docs_${doc_id}_${written}")
            endif()
          endforeach()
          list(APPEND required ${fixture})
        endif()
        list(APPEND args ${mapped})
      else()
        list(APPEND args "${tok}")
      endif()
      set(previous "${tok}")
    endforeach()
    set(extra "")
    if(writes_results)
      # `results/` exists when the docs' commands run in order (docs/usage.md).
      list(APPEND extra MAKE_DIRECTORY ${results})
    endif()
    if(setup)
      list(APPEND extra FIXTURES_SETUP ${setup})
    endif()
    if(required)
      list(APPEND extra FIXTURES_REQUIRED ${required})
    endif()
    if(locks)
      list(APPEND extra RESOURCE_LOCK ${locks})
    endif()
    sf_gsa_cli_test(docs.${doc_id}.L${pending_line} COMMAND ${args} ${extra})
  endforeach()
endforeach()

# gsa plot with another forming limit curve: the zones of gsa analyse's curve are not
# carried over (zones.png dropped, the report without the old counts).
set(sf_zones ${SF_CLI_DIR}/zones)
sf_gsa_cli_test(zones_analyse
  COMMAND analyse data/gsa/dome/grid.csv --thickness 1 --flc-n 0.22 --out ${sf_zones}
  REMOVE ${sf_zones}
  EXISTS "${sf_zones}/zones.png"
  FIXTURES_SETUP gsa_zones)
sf_gsa_cli_test(zones_plot_other_curve
  COMMAND plot ${sf_zones} --flc data/flc/illustrative.csv
  ABSENT "${sf_zones}/zones.png"
  EXISTS "${sf_zones}/report.html"
  FIXTURES_REQUIRED gsa_zones)
sf_gsa_cli_test(zones_analyse_table
  COMMAND analyse data/gsa/dome/grid.csv --thickness 1 --flc data/flc/illustrative.csv --out ${sf_zones}_table
  REMOVE ${sf_zones}_table
  EXISTS "${sf_zones}_table/zones.png"
  FIXTURES_SETUP gsa_zones_table)
sf_gsa_cli_test(zones_plot_same_curve
  COMMAND plot ${sf_zones}_table --flc data/flc/illustrative.csv
  EXISTS "${sf_zones}_table/zones.png"
  STDERR "120 of 441 marks beyond"
  FIXTURES_REQUIRED gsa_zones_table)
