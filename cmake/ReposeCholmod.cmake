# CHOLMOD (SuiteSparse 5, Debian 12 ships no CMake config for it): an imported target used
# privately by ReposeCore's sparse solvers, through Eigen's CholmodSupport module.
find_path(REPOSE_CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(REPOSE_CHOLMOD_LIBRARY NAMES cholmod REQUIRED)
find_library(REPOSE_SUITESPARSECONFIG_LIBRARY NAMES suitesparseconfig REQUIRED)
if(NOT TARGET Repose::cholmod)
  add_library(Repose::cholmod UNKNOWN IMPORTED)
  set_target_properties(Repose::cholmod PROPERTIES
    IMPORTED_LOCATION "${REPOSE_CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${REPOSE_CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${REPOSE_SUITESPARSECONFIG_LIBRARY}")
endif()
