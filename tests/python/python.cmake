# The Python module (issue 32): pytest on Debian's python3 with the build tree's package, against
# the aerocal binary of the same build (tools/python/README.md).
if(AEROCAL_BUILD_PYTHON)
  add_test(NAME python/aerocal
    COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider ${CMAKE_CURRENT_LIST_DIR})
  set_tests_properties(python/aerocal PROPERTIES LABELS cli TIMEOUT 600 ENVIRONMENT
    "PYTHONPATH=${CMAKE_BINARY_DIR}/python;AEROCAL_BINARY=$<TARGET_FILE:aerocal>;AEROCAL_SOURCE_DIR=${PROJECT_SOURCE_DIR};PYTHONDONTWRITEBYTECODE=1")
endif()
