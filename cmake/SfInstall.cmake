# Installation (GNUInstallDirs) and the Debian package (CPack DEB); docs/install.md.
#
#   cmake --install build --prefix /opt/sheetform      # or the default /usr/local
#   (cd build && cpack -G DEB)                           # build/sheetform_<version>_<arch>.deb
#
# Layout under the prefix:
#   bin/gsa, bin/simform
#   share/sheetform/data/...            the sample data (grids, cases, FLC, format examples)
#   share/doc/sheetform/...             README.md, docs/
#   share/man/man1/gsa.1, simform.1     generated from --help (cmake/SfHelpPages.cmake)
#   share/bash-completion/completions/  gsa, simform (generated from --help)
#   lib/python3/dist-packages/sheetform the Python module, when built (python/)
#
# The executables read no installed file at run time (colour maps and fonts are compiled
# in or VTK's own); nothing of the build tree is compiled into them.
include(GNUInstallDirs)

install(TARGETS gsa simform RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/ DESTINATION ${CMAKE_INSTALL_DATADIR}/sheetform/data
        PATTERN "*.py" EXCLUDE)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})

# Man pages and bash completions from the programs' own --help, at build time.
set(SF_HELP_DIR ${PROJECT_BINARY_DIR}/help)
set(SF_HELP_OUTPUTS "")
foreach(tool gsa simform)
  add_custom_command(
    OUTPUT ${SF_HELP_DIR}/${tool}.1 ${SF_HELP_DIR}/completions/${tool}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${SF_HELP_DIR}/completions
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:${tool}> -DNAME=${tool} -DVERSION=${PROJECT_VERSION}
            -DMAN=${SF_HELP_DIR}/${tool}.1 -DCOMPLETION=${SF_HELP_DIR}/completions/${tool}
            -P ${PROJECT_SOURCE_DIR}/cmake/SfHelpPages.cmake
    DEPENDS ${tool} ${PROJECT_SOURCE_DIR}/cmake/SfHelpPages.cmake
    COMMENT "Man page and bash completion of ${tool} from its --help"
    VERBATIM)
  list(APPEND SF_HELP_OUTPUTS ${SF_HELP_DIR}/${tool}.1 ${SF_HELP_DIR}/completions/${tool})
  install(FILES ${SF_HELP_DIR}/${tool}.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
  install(FILES ${SF_HELP_DIR}/completions/${tool} DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
endforeach()
add_custom_target(sf_help_pages ALL DEPENDS ${SF_HELP_OUTPUTS})

# ------------------------------------------------------------------ Debian package
set(CPACK_PACKAGE_NAME sheetform)
set(CPACK_PACKAGE_VENDOR "sheetform developers")
set(CPACK_PACKAGE_CONTACT "sheetform developers <sheetform@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "grid strain analysis (gsa) and forming simulation (simform) for sheet parts")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_GENERATOR DEB)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "grid strain analysis and forming simulation for sheet parts\n gsa: principal strains, thickness change and fibre shear of formed sheet parts\n from digitised grid marks, by bicubic Hermite surface fits. simform: a\n nonlinear finite element forming solver for fibre-reinforced plies.")
# Depends: the runtime library packages of the linked shared libraries, found by
# dpkg-shlibdeps (never the -dev packages the build needs). Xvfb draws the pictures
# on machines without a display.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "xvfb, xauth")
if(SF_PYTHON_MODULE_BUILT)
  # The module needs Python 3 and NumPy only when imported.
  set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "${CPACK_DEBIAN_PACKAGE_RECOMMENDS}, python3, python3-numpy")
  set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3-pandas")
endif()
include(CPack)
