# Finds OpenSubdiv's CPU library and headers.
#
# Debian's OpenSubdivConfig.cmake lists static libraries (libosdCPU.a, libosdGPU.a) the package does not
# install, so find_package(OpenSubdiv CONFIG) fails. This module finds the header and the shared osdCPU
# library directly (osdGPU is not needed and would drag in OpenGL).
#
# Defines the imported target OpenSubdiv::osdCPU and OpenSubdiv_FOUND, OpenSubdiv_INCLUDE_DIR,
# OpenSubdiv_LIBRARY, OpenSubdiv_VERSION.
find_path(OpenSubdiv_INCLUDE_DIR NAMES opensubdiv/far/topologyRefiner.h)
find_library(OpenSubdiv_LIBRARY NAMES osdCPU)

if(OpenSubdiv_INCLUDE_DIR AND EXISTS "${OpenSubdiv_INCLUDE_DIR}/opensubdiv/version.h")
  foreach(_part MAJOR MINOR PATCH)
    file(STRINGS "${OpenSubdiv_INCLUDE_DIR}/opensubdiv/version.h" _osd_line
         REGEX "#define OPENSUBDIV_VERSION_${_part} ")
    string(REGEX REPLACE ".*_${_part} ([0-9]+).*" "\\1" _osd_${_part} "${_osd_line}")
  endforeach()
  set(OpenSubdiv_VERSION "${_osd_MAJOR}.${_osd_MINOR}.${_osd_PATCH}")
endif()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenSubdiv REQUIRED_VARS OpenSubdiv_LIBRARY OpenSubdiv_INCLUDE_DIR
                                  VERSION_VAR OpenSubdiv_VERSION)

if(OpenSubdiv_FOUND AND NOT TARGET OpenSubdiv::osdCPU)
  add_library(OpenSubdiv::osdCPU UNKNOWN IMPORTED)
  set_target_properties(OpenSubdiv::osdCPU PROPERTIES IMPORTED_LOCATION "${OpenSubdiv_LIBRARY}"
                        INTERFACE_INCLUDE_DIRECTORIES "${OpenSubdiv_INCLUDE_DIR}")
endif()
mark_as_advanced(OpenSubdiv_INCLUDE_DIR OpenSubdiv_LIBRARY)
