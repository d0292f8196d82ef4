# Tests of installing, packaging, `gsa batch` and the Python module (issue 19; docs/install.md,
# docs/batch.md, docs/python.md). Included by tests/CMakeLists.txt.
#
#  - install.prefix:         cmake --install into a temporary prefix, run from another folder
#  - package.deb:            cpack -G DEB (into build/package-test/); the control file lists
#                            runtime packages only
#  - package.dpkg_install:   dpkg -i that package, gsa analyse, dpkg -r (root with CI set;
#                            else skipped)
#  - gsa.batch.cli:          gsa batch with a broken part, --collect, a list, bad options
#  - python.sheetform:       Python's unittest on the module (when it is built)
if(NOT TARGET gsa OR NOT TARGET simform)
  return()
endif()

set(SF_INSTALL_TEST_PYTHON "")
if(SF_PYTHON_MODULE_BUILT)
  set(SF_INSTALL_TEST_PYTHON ${SF_PYTHON_EXECUTABLE})
endif()
add_test(NAME install.prefix
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/install/check_install.sh ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
                 ${SF_INSTALL_TEST_PYTHON})
set_tests_properties(install.prefix PROPERTIES LABELS "install" TIMEOUT 300)

add_test(NAME package.deb COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/install/check_package.sh control ${PROJECT_BINARY_DIR})
# cpack compresses the whole install: minutes on a loaded 2-core machine.
set_tests_properties(package.deb PROPERTIES LABELS "install" TIMEOUT 1500 FIXTURES_SETUP sf_deb_package)
add_test(NAME package.dpkg_install
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/install/check_package.sh dpkg ${PROJECT_BINARY_DIR})
set_tests_properties(package.dpkg_install PROPERTIES LABELS "install" TIMEOUT 600 SKIP_RETURN_CODE 77
                                                     RESOURCE_LOCK sf_system_packages FIXTURES_REQUIRED sf_deb_package)

add_test(NAME gsa.batch.cli
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/batch/check_batch.sh $<TARGET_FILE:gsa> ${PROJECT_SOURCE_DIR}
                 ${PROJECT_BINARY_DIR}/cli/batch)
set_tests_properties(gsa.batch.cli PROPERTIES LABELS "gsa;cli" TIMEOUT 300)

if(SF_PYTHON_MODULE_BUILT)
  add_test(NAME python.sheetform
           COMMAND ${SF_PYTHON_EXECUTABLE} -m unittest discover -v -s ${CMAKE_CURRENT_LIST_DIR}/python -p "test_*.py")
  set_tests_properties(python.sheetform PROPERTIES LABELS "python" TIMEOUT 300
    ENVIRONMENT "PYTHONPATH=${SF_PYTHON_DIR};SF_GSA=$<TARGET_FILE:gsa>;SF_SOURCE_DIR=${PROJECT_SOURCE_DIR};SF_WORK_DIR=${PROJECT_BINARY_DIR}/cli/python")
  add_dependencies(sheetform_core gsa)
else()
  message(STATUS "Python tests: skipped (the module sheetform is not built)")
endif()

if(SF_PYTHON_MODULE_BUILT)
  # The notebook-style example of docs/python.md runs as written.
  add_test(NAME python.example COMMAND ${SF_PYTHON_EXECUTABLE} ${PROJECT_SOURCE_DIR}/docs/examples/sheetform_example.py)
  set_tests_properties(python.example PROPERTIES LABELS "python" TIMEOUT 120 ENVIRONMENT "PYTHONPATH=${SF_PYTHON_DIR}"
                                                 PASS_REGULAR_EXPRESSION "UsageError: --smoothing-scale")
endif()
