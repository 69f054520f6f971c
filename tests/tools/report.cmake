# tools/report: the flight report renderer (tools/report/aerocal_report.py, Python with Debian's
# python3-matplotlib), tested with python unittest on the fixture tests/data/report/result.json.
# Paths are taken from this file's folder, so it can be included from any scope.
# Debian's interpreter first: another python3 earlier in PATH (virtualenv, pyenv) may lack matplotlib.
find_program(AEROCAL_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(AEROCAL_PYTHON3 NAMES python3)
get_filename_component(AEROCAL_REPORT_ROOT "${CMAKE_CURRENT_LIST_DIR}/../.." ABSOLUTE)
add_test(NAME tools/report
  COMMAND ${AEROCAL_PYTHON3} -m unittest -v report_test
  WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(tools/report PROPERTIES LABELS cli TIMEOUT 180 ENVIRONMENT
  "PYTHONDONTWRITEBYTECODE=1;AEROCAL_REPORT_SCRIPT=${AEROCAL_REPORT_ROOT}/tools/report/aerocal_report.py;AEROCAL_REPORT_FIXTURE=${AEROCAL_REPORT_ROOT}/tests/data/report/result.json")
# The renderers (report, certificate, rig error plots) read only keys their input's schema lists
# (docs/schema; issue 30 item 5): each runs on a result `aerocal validate` accepted, its key
# lookups recorded and checked against the schema.
add_test(NAME tools/schema_keys
  COMMAND ${AEROCAL_PYTHON3} -m unittest -v schema_keys_test
  WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(tools/schema_keys PROPERTIES LABELS cli TIMEOUT 300 ENVIRONMENT
  "PYTHONDONTWRITEBYTECODE=1;AEROCAL_BINARY=$<TARGET_FILE:aerocal>")
