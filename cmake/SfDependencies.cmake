# All dependencies come from Debian 12 packages; nothing is downloaded at configure time.
find_package(Eigen3 3.4 REQUIRED CONFIG)
find_package(fmt REQUIRED CONFIG)
find_package(nlohmann_json 3 REQUIRED CONFIG)
find_package(CLI11 REQUIRED CONFIG)
find_package(yaml-cpp REQUIRED CONFIG)
find_package(CGAL 5.5 REQUIRED)
find_package(VTK 9 REQUIRED COMPONENTS CommonCore CommonDataModel IOXML IOImage FiltersCore
             FiltersSources FiltersModeling RenderingCore RenderingOpenGL2
             RenderingAnnotation RenderingFreeType)
# OpenCV: camera calibration and image processing of `gsa calibrate` / `gsa digitise`
# (gsa/digitise/*.cpp only; never in a public header).
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc calib3d imgcodecs features2d)
set(SF_OPENCV_LIBS opencv_core opencv_imgproc opencv_calib3d opencv_imgcodecs opencv_features2d)
# Xlib, to test a DISPLAY before VTK opens it (optional: VTK builds without X need none).
find_package(X11 QUIET)

# SuiteSparse: newer releases ship SuiteSparse::CHOLMOD / UMFPACK config packages;
# Debian 12's 5.12 ships none, so we wrap the libraries ourselves.
find_package(CHOLMOD CONFIG QUIET)
find_package(UMFPACK CONFIG QUIET)
if(TARGET SuiteSparse::CHOLMOD AND TARGET SuiteSparse::UMFPACK)
  add_library(sf_suitesparse INTERFACE)
  target_link_libraries(sf_suitesparse INTERFACE SuiteSparse::CHOLMOD SuiteSparse::UMFPACK)
else()
  find_path(SF_CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
  find_library(SF_CHOLMOD_LIBRARY cholmod REQUIRED)
  find_library(SF_UMFPACK_LIBRARY umfpack REQUIRED)
  add_library(sf_suitesparse INTERFACE)
  target_include_directories(sf_suitesparse SYSTEM INTERFACE ${SF_CHOLMOD_INCLUDE_DIR})
  target_link_libraries(sf_suitesparse INTERFACE ${SF_CHOLMOD_LIBRARY} ${SF_UMFPACK_LIBRARY})
endif()

# MUMPS, sequential build (Debian's libmumps-seq-dev; no MPI): the symmetric-indefinite
# LDL^T with pivoting that factorises a Newton tangent Cholesky cannot (common/linalg/solver.hpp,
# forming/solve/tangent_solver.hpp). Optional: without it such tangents go to UMFPACK's LU.
find_path(SF_MUMPS_INCLUDE_DIR dmumps_c.h)
find_library(SF_DMUMPS_LIBRARY dmumps_seq)
find_library(SF_MUMPS_COMMON_LIBRARY mumps_common_seq)
find_library(SF_MUMPS_MPISEQ_LIBRARY mpiseq_seq)
add_library(sf_mumps INTERFACE)
if(SF_MUMPS_INCLUDE_DIR AND SF_DMUMPS_LIBRARY AND SF_MUMPS_COMMON_LIBRARY AND SF_MUMPS_MPISEQ_LIBRARY)
  target_include_directories(sf_mumps SYSTEM INTERFACE ${SF_MUMPS_INCLUDE_DIR})
  target_link_libraries(sf_mumps INTERFACE ${SF_DMUMPS_LIBRARY} ${SF_MUMPS_COMMON_LIBRARY} ${SF_MUMPS_MPISEQ_LIBRARY})
  target_compile_definitions(sf_mumps INTERFACE SF_LINALG_HAVE_MUMPS=1)
  message(STATUS "MUMPS (sequential): ${SF_DMUMPS_LIBRARY}")
else()
  message(WARNING "MUMPS (sequential) not found: install Debian's libmumps-seq-dev (scripts/install_deps.sh). "
                  "Building without it: the solver kinds 'mumps' and 'mumps-ldlt' are unavailable and a "
                  "symmetric Newton tangent that is not positive definite is factorised by UMFPACK's LU.")
endif()

find_package(Threads REQUIRED)
# OpenMP (GCC's libgomp): the threaded element loop of simform's assembly.
find_package(OpenMP REQUIRED COMPONENTS CXX)
if(SF_BUILD_TESTS)
  find_package(GTest REQUIRED CONFIG)
  include(GoogleTest)
endif()
