# Installs the build tree into a fresh temporary prefix and runs test_dcm.py
# with Debian's /usr/bin/python3 on the module installed there.
#
#   cmake -DDCM_BUILD_DIR=... -DDCM_SOURCE_DIR=... -DDCM_PYTHON_INSTALL_DIR=... -P installed_module_test.cmake
foreach(_v DCM_BUILD_DIR DCM_SOURCE_DIR DCM_PYTHON_INSTALL_DIR)
  if(NOT DEFINED ${_v})
    message(FATAL_ERROR "${_v} not set")
  endif()
endforeach()

execute_process(COMMAND mktemp -d /tmp/dcm-python-test.XXXXXX OUTPUT_VARIABLE _tmp
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0 OR NOT IS_DIRECTORY "${_tmp}")
  message(FATAL_ERROR "mktemp failed")
endif()
set(_prefix "${_tmp}/prefix")

execute_process(COMMAND ${CMAKE_COMMAND} --install "${DCM_BUILD_DIR}" --prefix "${_prefix}"
                RESULT_VARIABLE _rc OUTPUT_QUIET ERROR_VARIABLE _err)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed:\n${_err}")
endif()
set(_site "${_prefix}/${DCM_PYTHON_INSTALL_DIR}")
if(NOT EXISTS "${_site}/dcm/__init__.py")
  message(FATAL_ERROR "not installed: ${_site}/dcm/__init__.py")
endif()

execute_process(
  COMMAND ${CMAKE_COMMAND} -E env "PYTHONPATH=${_site}" "DCM_PREFIX=${_prefix}" "DCM_EXE=${_prefix}/bin/dcm"
          "DCM_MAKE_AOVS=${DCM_SOURCE_DIR}/examples/aov/make_aovs.py"
          "DCM_EXAMPLE=${DCM_SOURCE_DIR}/examples/python/reconstruct.py"
          /usr/bin/python3 "${DCM_SOURCE_DIR}/tests/python/test_dcm.py"
  WORKING_DIRECTORY "${_tmp}" RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
message("${_out}${_err}")
file(REMOVE_RECURSE "${_tmp}")
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "test_dcm.py failed (${_rc})")
endif()
