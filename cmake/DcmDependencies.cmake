# Finds the Debian 12 packages dcm builds on, with work-arounds for their
# packaging bugs (see ../shared/BUILD-NOTES.md).

find_package(TBB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)

find_package(OpenImageIO REQUIRED)
include(dcmFixOpenImageIO)
dcm_fix_openimageio_targets()
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
