# Debian 12's OpenImageIO package lists /usr/include/opencv4 as an include
# directory although no installed package provides it, and CMake refuses an
# imported target with a missing include directory: drop the missing ones.
# Used by the build (DcmDependencies.cmake) and by the installed dcm package
# (dcmConfig.cmake, for dcm::aov).
function(dcm_fix_openimageio_targets)
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
endfunction()
