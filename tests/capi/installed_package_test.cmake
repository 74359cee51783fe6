# Installs the build tree into a fresh temporary prefix, builds examples/c-api
# against it as a separate CMake project (find_package(dcm)) and again with
# pkg-config only, outside the source tree, runs both and checks their output.
# Builds cxx_consumer (dcm::engine + dcm::aov, no CMAKE_CXX_STANDARD) and runs
# it on AOVs of examples/aov/make_aovs.py. Checks that every command answers
# --version and that libdcm.so needs at run time only what its comments say.
#
#   cmake -DDCM_BUILD_DIR=... -DDCM_EXAMPLE_DIR=... -DDCM_CXX_CONSUMER_DIR=... -DDCM_MAKE_AOVS=...
#         -DDCM_GENERATOR=... -P installed_package_test.cmake
foreach(_v DCM_BUILD_DIR DCM_EXAMPLE_DIR DCM_CXX_CONSUMER_DIR DCM_MAKE_AOVS DCM_GENERATOR)
  if(NOT DEFINED ${_v})
    message(FATAL_ERROR "${_v} not set")
  endif()
endforeach()

execute_process(COMMAND mktemp -d /tmp/dcm-capi-test.XXXXXX OUTPUT_VARIABLE _tmp
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0 OR NOT IS_DIRECTORY "${_tmp}")
  message(FATAL_ERROR "mktemp failed")
endif()
set(_prefix "${_tmp}/prefix")
set(_build "${_tmp}/build")

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

# The example's output: exact fraction in (0,1), the callback's count equal to
# the engine's, the error against the analytic truth small, "OK".
function(check_example_output out label)
  if(NOT out MATCHES "exact fraction +([0-9.]+)")
    message(FATAL_ERROR "${label}: no exact fraction in:\n${out}")
  endif()
  set(_f "${CMAKE_MATCH_1}")
  if(NOT _f GREATER 0 OR NOT _f LESS 0.2)
    message(FATAL_ERROR "${label}: exact fraction ${_f} not in (0, 0.2)")
  endif()
  if(NOT out MATCHES "exact pixels +([0-9]+) of ([0-9]+)")
    message(FATAL_ERROR "${label}: no exact pixel count in:\n${out}")
  endif()
  set(_exact "${CMAKE_MATCH_1}")
  if(NOT out MATCHES "callback +([0-9]+) pixels")
    message(FATAL_ERROR "${label}: no callback count in:\n${out}")
  endif()
  if(NOT CMAKE_MATCH_1 EQUAL _exact)
    message(FATAL_ERROR "${label}: callback evaluated ${CMAKE_MATCH_1} pixels, the engine reports ${_exact}")
  endif()
  if(NOT out MATCHES "mean abs error +([0-9.]+)" OR NOT CMAKE_MATCH_1 LESS 0.002)
    message(FATAL_ERROR "${label}: mean error too large or missing:\n${out}")
  endif()
  if(NOT out MATCHES "rejected option +method: unknown value")
    message(FATAL_ERROR "${label}: the unknown method was not reported:\n${out}")
  endif()
  if(NOT out MATCHES "\nOK\n")
    message(FATAL_ERROR "${label}: no OK:\n${out}")
  endif()
  message(STATUS "${label}: exact fraction ${_f}, ${_exact} exact pixels")
endfunction()

run("cmake --install" ${CMAKE_COMMAND} --install "${DCM_BUILD_DIR}" --prefix "${_prefix}")
foreach(_f include/dcm/dcm.h include/dcm/reconstructor.h lib/libdcm.so bin/dcm lib/cmake/dcm/dcmConfig.cmake
           lib/pkgconfig/dcm.pc share/dcm/blender/child_main.py share/dcm/blender/render_main.py)
  if(NOT EXISTS "${_prefix}/${_f}")
    message(FATAL_ERROR "not installed: ${_f}")
  endif()
endforeach()
run("installed dcm --version" "${_prefix}/bin/dcm" --version)
if(NOT run_output MATCHES "^dcm [0-9]")
  message(FATAL_ERROR "installed dcm --version printed: ${run_output}")
endif()
set(_version "${run_output}")
# Every command listed by --help answers --version alike.
run("installed dcm --help" "${_prefix}/bin/dcm" --help)
string(REGEX MATCH "Subcommands:.*" _subs "${run_output}")
string(REGEX MATCHALL "\n +[a-z]+ " _subs "${_subs}")
list(LENGTH _subs _nsubs)
if(_nsubs LESS 3)
  message(FATAL_ERROR "dcm --help lists ${_nsubs} commands:\n${run_output}")
endif()
foreach(_sub IN LISTS _subs)
  string(STRIP "${_sub}" _sub)
  run("dcm ${_sub} --version" "${_prefix}/bin/dcm" ${_sub} --version)
  if(NOT run_output STREQUAL _version)
    message(FATAL_ERROR "dcm ${_sub} --version printed '${run_output}', dcm --version '${_version}'")
  endif()
endforeach()

# libdcm.so needs, besides the C++ runtime, oneTBB's libtbb.so.12 (as
# dcm.pc and dcmConfig.cmake say) and nothing else.
find_program(_readelf readelf REQUIRED)
run("readelf libdcm.so" ${_readelf} -d "${_prefix}/lib/libdcm.so")
string(REGEX MATCHALL "Shared library: \\[[^]]+\\]" _needed "${run_output}")
foreach(_lib IN LISTS _needed)
  if(NOT _lib MATCHES "\\[(libtbb\\.so\\.12|libstdc\\+\\+\\.so\\.6|libm\\.so\\.6|libgcc_s\\.so\\.1|libc\\.so\\.6|ld-linux-x86-64\\.so\\.2)\\]")
    message(FATAL_ERROR "libdcm.so needs ${_lib}, which dcm.pc and dcmConfig.cmake do not mention")
  endif()
endforeach()
if(NOT _needed MATCHES "libtbb")
  message(FATAL_ERROR "libdcm.so no longer needs libtbb: update dcm.pc.in and dcmConfig.cmake.in")
endif()

# 1. find_package(dcm) in a separate project.
run("configure the example" ${CMAKE_COMMAND} -S "${DCM_EXAMPLE_DIR}" -B "${_build}" -G "${DCM_GENERATOR}"
    -DCMAKE_PREFIX_PATH=${_prefix} -DCMAKE_BUILD_TYPE=Release)
run("build the example" ${CMAKE_COMMAND} --build "${_build}")
run("run the example (CMake)" "${_build}/dcm_c_example")
check_example_output("${run_output}" "find_package(dcm)")

# 2. pkg-config only.
find_program(_pkgconfig pkg-config)
find_program(_cc NAMES cc gcc)
if(_pkgconfig AND _cc)
  set(ENV{PKG_CONFIG_PATH} "${_prefix}/lib/pkgconfig")
  run("pkg-config" ${_pkgconfig} --cflags --libs dcm)
  string(STRIP "${run_output}" _flags)
  separate_arguments(_flags UNIX_COMMAND "${_flags}")
  run("compile with pkg-config" ${_cc} -std=c99 -Wall -Wextra -Wpedantic -Werror
      "${DCM_EXAMPLE_DIR}/analytic_example.c" -o "${_tmp}/example_pc" ${_flags} -lm -Wl,-rpath,${_prefix}/lib)
  run("run the example (pkg-config)" "${_tmp}/example_pc")
  check_example_output("${run_output}" "pkg-config")
else()
  message(FATAL_ERROR "pkg-config or a C compiler is missing")
endif()

# 3. C++: dcm::engine and dcm::aov at the compiler's default standard.
run("configure the C++ consumer" ${CMAKE_COMMAND} -S "${DCM_CXX_CONSUMER_DIR}" -B "${_tmp}/build-cxx"
    -G "${DCM_GENERATOR}" -DCMAKE_PREFIX_PATH=${_prefix} -DCMAKE_BUILD_TYPE=Release)
run("build the C++ consumer" ${CMAKE_COMMAND} --build "${_tmp}/build-cxx")
run("make AOVs" /usr/bin/python3 "${DCM_MAKE_AOVS}" "${_tmp}/aovs.exr" 64)
run("run the C++ consumer" "${_tmp}/build-cxx/dcm_cxx_consumer" "${_tmp}/aovs.exr")
if(NOT run_output MATCHES "missing file: [^\n]*no-such-file\\.exr")
  message(FATAL_ERROR "C++ consumer: the missing file is not named:\n${run_output}")
endif()
# A dense 64x64 input: a few hundred exact pixels, an error at the scale of
# the scene's texture steps on its edge pixels (the mean over the image
# stays below 1 %).
if(NOT run_output MATCHES "size 64x64" OR NOT run_output MATCHES "exact fraction ([0-9.]+)")
  message(FATAL_ERROR "C++ consumer:\n${run_output}")
endif()
if(NOT CMAKE_MATCH_1 GREATER 0 OR NOT CMAKE_MATCH_1 LESS 0.6)
  message(FATAL_ERROR "C++ consumer: exact fraction ${CMAKE_MATCH_1} not in (0, 0.6)")
endif()
if(NOT run_output MATCHES "mean abs error ([0-9.]+)" OR NOT CMAKE_MATCH_1 LESS 0.01 OR NOT run_output MATCHES "\nOK\n")
  message(FATAL_ERROR "C++ consumer: error too large or missing:\n${run_output}")
endif()
message(STATUS "C++ consumer (dcm::engine, dcm::aov): ${run_output}")

file(REMOVE_RECURSE "${_tmp}")
