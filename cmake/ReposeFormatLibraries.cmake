# Imported targets for the file-format libraries, found by hand because the CMake configs that
# Debian 12 ships for them point at files that do not exist: NIFTITargets.cmake names
# /usr/lib/libznz.so.3.0.0 and TeemLibraryDepends.cmake a path in Debian's build tree.

# niftilib: libnifti2 reads NIfTI-1 and NIfTI-2.
find_path(REPOSE_NIFTI_INCLUDE_DIR nifti2_io.h PATH_SUFFIXES nifti REQUIRED)
find_library(REPOSE_NIFTI2_LIBRARY NAMES nifti2 REQUIRED)
find_library(REPOSE_ZNZ_LIBRARY NAMES znz REQUIRED)
if(NOT TARGET Repose::nifti2)
  add_library(Repose::nifti2 UNKNOWN IMPORTED)
  set_target_properties(Repose::nifti2 PROPERTIES
    IMPORTED_LOCATION "${REPOSE_NIFTI2_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${REPOSE_NIFTI_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${REPOSE_ZNZ_LIBRARY};ZLIB::ZLIB;m")
endif()

# teem (NRRD), as 3D Slicer uses it.
find_path(REPOSE_TEEM_INCLUDE_DIR teem/nrrd.h REQUIRED)
find_library(REPOSE_TEEM_LIBRARY NAMES teem REQUIRED)
if(NOT TARGET Repose::teem)
  add_library(Repose::teem UNKNOWN IMPORTED)
  set_target_properties(Repose::teem PROPERTIES
    IMPORTED_LOCATION "${REPOSE_TEEM_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${REPOSE_TEEM_INCLUDE_DIR}")
endif()
