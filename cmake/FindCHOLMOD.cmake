# FindCHOLMOD: SuiteSparse CHOLMOD (Debian's SuiteSparse 5.12 ships no CMake config).
#
# Defines the imported target CHOLMOD::CHOLMOD and the variables CHOLMOD_FOUND,
# CHOLMOD_INCLUDE_DIR, CHOLMOD_LIBRARY and CHOLMOD_VERSION.
include(FindPackageHandleStandardArgs)

find_path(CHOLMOD_INCLUDE_DIR NAMES cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY NAMES cholmod)
find_library(CHOLMOD_SUITESPARSECONFIG_LIBRARY NAMES suitesparseconfig)
foreach(part AMD CAMD COLAMD CCOLAMD)
  string(TOLOWER ${part} lib)
  find_library(CHOLMOD_${part}_LIBRARY NAMES ${lib})
endforeach()

if(CHOLMOD_INCLUDE_DIR AND EXISTS "${CHOLMOD_INCLUDE_DIR}/cholmod.h")
  file(STRINGS "${CHOLMOD_INCLUDE_DIR}/cholmod.h" _cholmod_version_lines
       REGEX "#define CHOLMOD_(MAIN|SUB|SUBSUB)_VERSION")
  string(REGEX REPLACE ".*CHOLMOD_MAIN_VERSION +([0-9]+).*" "\\1" _major "${_cholmod_version_lines}")
  string(REGEX REPLACE ".*CHOLMOD_SUB_VERSION +([0-9]+).*" "\\1" _minor "${_cholmod_version_lines}")
  string(REGEX REPLACE ".*CHOLMOD_SUBSUB_VERSION +([0-9]+).*" "\\1" _patch "${_cholmod_version_lines}")
  set(CHOLMOD_VERSION "${_major}.${_minor}.${_patch}")
endif()

find_package_handle_standard_args(CHOLMOD
  REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_INCLUDE_DIR CHOLMOD_SUITESPARSECONFIG_LIBRARY
  VERSION_VAR CHOLMOD_VERSION)

if(CHOLMOD_FOUND AND NOT TARGET CHOLMOD::CHOLMOD)
  add_library(CHOLMOD::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(CHOLMOD::CHOLMOD PROPERTIES
    IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}")
  set(_deps ${CHOLMOD_SUITESPARSECONFIG_LIBRARY})
  foreach(part AMD CAMD COLAMD CCOLAMD)
    if(CHOLMOD_${part}_LIBRARY)
      list(APPEND _deps ${CHOLMOD_${part}_LIBRARY})
    endif()
  endforeach()
  set_property(TARGET CHOLMOD::CHOLMOD PROPERTY INTERFACE_LINK_LIBRARIES "${_deps}")
endif()
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY CHOLMOD_SUITESPARSECONFIG_LIBRARY
                 CHOLMOD_AMD_LIBRARY CHOLMOD_CAMD_LIBRARY CHOLMOD_COLAMD_LIBRARY CHOLMOD_CCOLAMD_LIBRARY)
