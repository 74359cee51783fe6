# Finds the Debian 12 packages dcm builds on, with work-arounds for their
# packaging bugs (see ../shared/BUILD-NOTES.md).

find_package(TBB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)

# OpenImageIO lists /usr/include/opencv4 as an include directory although no
# installed package provides it: drop non-existent include directories.
find_package(OpenImageIO REQUIRED)
foreach(_tgt OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${_tgt})
    get_target_property(_incs ${_tgt} INTERFACE_INCLUDE_DIRECTORIES)
    if(_incs)
      set(_kept)
      foreach(_d IN LISTS _incs)
        if(_d MATCHES "\\$<" OR EXISTS "${_d}")
          list(APPEND _kept "${_d}")
        endif()
      endforeach()
      set_target_properties(${_tgt} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
    endif()
  endif()
endforeach()
find_package(OpenEXR REQUIRED)
find_package(Imath REQUIRED)

# OpenColorIOConfig.cmake lives in /usr/share/cmake, which is not searched, and
# computes its include directory as /include.
find_package(OpenColorIO REQUIRED HINTS /usr/share/cmake)
if(TARGET OpenColorIO::OpenColorIO)
  set_target_properties(OpenColorIO::OpenColorIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES /usr/include)
endif()

if(DCM_BUILD_EMBREE)
  find_package(embree 3 REQUIRED)
endif()
