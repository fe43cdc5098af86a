# Imported targets for libraries whose Debian 12 CMake configs are broken or missing: the
# configs for niftilib (NIFTITargets.cmake names /usr/lib/libznz.so.3.0.0) and teem
# (TeemLibraryDepends.cmake names a path in Debian's build tree) point at files that do not
# exist, and SuiteSparse 5 ships none for CHOLMOD.

# repose_import_library(<target> HEADER <file> [SUFFIX <dir>] LIBRARY <name> [DEPENDS <libs...>])
function(repose_import_library target)
  cmake_parse_arguments(ARG "" "HEADER;SUFFIX;LIBRARY" "DEPENDS" ${ARGN})
  string(MAKE_C_IDENTIFIER "${target}" id)
  find_path(REPOSE_${id}_INCLUDE_DIR ${ARG_HEADER} PATH_SUFFIXES ${ARG_SUFFIX} REQUIRED)
  find_library(REPOSE_${id}_LIBRARY NAMES ${ARG_LIBRARY} REQUIRED)
  if(NOT TARGET ${target})
    add_library(${target} UNKNOWN IMPORTED GLOBAL)
    set_target_properties(${target} PROPERTIES
      IMPORTED_LOCATION "${REPOSE_${id}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${REPOSE_${id}_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "${ARG_DEPENDS}")
  endif()
endfunction()

find_library(REPOSE_ZNZ_LIBRARY NAMES znz REQUIRED)
find_library(REPOSE_SUITESPARSECONFIG_LIBRARY NAMES suitesparseconfig REQUIRED)
# libnifti2 reads NIfTI-1 and NIfTI-2.
repose_import_library(Repose::nifti2 HEADER nifti2_io.h SUFFIX nifti LIBRARY nifti2
  DEPENDS ${REPOSE_ZNZ_LIBRARY} ZLIB::ZLIB m)
# teem for NRRD, as 3D Slicer uses it.
repose_import_library(Repose::teem HEADER teem/nrrd.h LIBRARY teem)
# CHOLMOD through Eigen's CholmodSupport.
repose_import_library(Repose::cholmod HEADER cholmod.h SUFFIX suitesparse LIBRARY cholmod
  DEPENDS ${REPOSE_SUITESPARSECONFIG_LIBRARY})
