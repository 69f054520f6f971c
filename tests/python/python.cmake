# The Python module (issue 32): pytest on Debian's python3 with the build tree's package, against
# the aerocal binary of the same build (tools/python/README.md). One ctest test per file, so that
# ctest -j runs them side by side: python/aerocal, python/examples, python/pip_install.
if(AEROCAL_BUILD_PYTHON)
  foreach(name aerocal examples pip_install)
    add_test(NAME python/${name}
      COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider
              ${CMAKE_CURRENT_LIST_DIR}/test_${name}.py)
    set_tests_properties(python/${name} PROPERTIES LABELS cli TIMEOUT 600 ENVIRONMENT
      "PYTHONPATH=${CMAKE_BINARY_DIR}/python;AEROCAL_BINARY=$<TARGET_FILE:aerocal>;AEROCAL_SOURCE_DIR=${PROJECT_SOURCE_DIR};PYTHONDONTWRITEBYTECODE=1")
  endforeach()
endif()
