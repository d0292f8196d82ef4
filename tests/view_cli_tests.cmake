# gsa's interactive 3-D view (issue 17 item 4, gsa/view3d.hpp, docs/usage.md "3-D view"):
# report.html and `gsa view DIR` (view.html) on the dome sample, and both pages opened in
# headless Chromium (tests/gsa/view3d_browser.py: no console error, a canvas that is not
# blank, a rotated view that differs, a click that reads values). The browser tests skip
# (exit 77) where Chromium is absent; scripts/install_deps.sh installs it, so CI runs them.
# Included by tests/CMakeLists.txt after cli_tests.cmake (sf_gsa_cli_test, SF_CLI_DIR).
if(NOT TARGET gsa OR NOT COMMAND sf_gsa_cli_test)
  return()
endif()
if(NOT EXISTS "${SF_THREE_JS_DIR}/three.min.js")
  message(STATUS "gsa 3-D view tests left out: gsa builds without three.js (libjs-three)")
  return()
endif()

set(view_dir ${SF_CLI_DIR}/view)
sf_gsa_cli_test(view.analyse_dome
  COMMAND analyse ${PROJECT_SOURCE_DIR}/data/gsa/dome/grid.csv --out ${view_dir}/dome
  EXISTS ${view_dir}/dome/report.html FIXTURES_SETUP gsa_view_dome)
sf_gsa_cli_test(view.write
  COMMAND view ${view_dir}/dome
  STDERR "wrote .*view.html \\(6272 triangles, 8x8 per element, 441 marks"
  EXISTS ${view_dir}/dome/view.html FIXTURES_REQUIRED gsa_view_dome FIXTURES_SETUP gsa_view_page)
sf_gsa_cli_test(view.decimated
  COMMAND view ${view_dir}/dome --max-vertices 1000 --out ${view_dir}/dome_decimated.html
  STDERR "wrote .*dome_decimated.html \\(392 triangles, 2x2 per element"
  EXISTS ${view_dir}/dome_decimated.html FIXTURES_REQUIRED gsa_view_dome)
sf_gsa_cli_test(view.missing_folder
  COMMAND view ${view_dir}/no_such_folder EXIT 1 STDERR "no_such_folder: no such folder")
sf_gsa_cli_test(view.bad_budget
  COMMAND view ${view_dir}/dome --max-vertices 5 EXIT 2 STDERR "--max-vertices: must be at least 100, found 5"
  FIXTURES_REQUIRED gsa_view_dome)
sf_gsa_cli_test(view.analyse_triangles
  COMMAND analyse ${PROJECT_SOURCE_DIR}/data/gsa/dome/grid.csv --method triangles --no-plots
          --out ${view_dir}/triangles
  FIXTURES_SETUP gsa_view_triangles)
sf_gsa_cli_test(view.triangles
  COMMAND view ${view_dir}/triangles EXIT 1 STDERR "3-D view needs the surface method"
  ABSENT ${view_dir}/triangles/view.html FIXTURES_REQUIRED gsa_view_triangles)

find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  foreach(page view report)
    add_test(NAME gsa.view.browser_${page}
             COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/gsa/view3d_browser.py
                     ${view_dir}/dome/${page}.html --shots ${view_dir}/shots)
    set_tests_properties(gsa.view.browser_${page} PROPERTIES
      LABELS "gsa;browser" TIMEOUT 300 SKIP_RETURN_CODE 77 RESOURCE_LOCK chromium
      FIXTURES_REQUIRED "gsa_view_dome;gsa_view_page")
  endforeach()
endif()
