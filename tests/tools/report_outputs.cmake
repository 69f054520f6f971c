# What people open elsewhere and what they read (issue 33), Python unittest with Debian's python3:
# - tools/tables: `aerocal export --tables` on the report fixture (a flight result) and on the
#   real ODM block (skipped without ../shared/data), read back with csv / pandas and json (cli);
# - tools/render: the ODM block's and a flight's reports and a test field's certificate rendered
#   (HTML -> PNG by headless chromium, PDF -> PNG by pdftoppm), sections present, nothing past
#   the page box; seconds per page, so label long (`ctest -L render`); skipped without chromium;
# - tools/render_pdf: the same without chromium (AEROCAL_RENDER_PARTS=pdf): the PDFs typeset by
#   WeasyPrint, rasterised by pdftoppm, every page's ink inside its margins (cli: in CI).
# AEROCAL_PYTHON3 comes from report.cmake (included before this file).
get_filename_component(AEROCAL_REPORT_OUTPUTS_ROOT "${CMAKE_CURRENT_LIST_DIR}/../.." ABSOLUTE)
set(AEROCAL_REPORT_OUTPUTS_ENV
  "PYTHONDONTWRITEBYTECODE=1;AEROCAL_BINARY=$<TARGET_FILE:aerocal>;AEROCAL_SHARED_DATA_DIR=${AEROCAL_SHARED_DATA_DIR}")
add_test(NAME tools/tables
  COMMAND ${AEROCAL_PYTHON3} -m unittest -v tables_test
  WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(tools/tables PROPERTIES LABELS cli TIMEOUT 300 ENVIRONMENT "${AEROCAL_REPORT_OUTPUTS_ENV}")
add_test(NAME tools/render
  COMMAND ${AEROCAL_PYTHON3} -m unittest -v render_test
  WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(tools/render PROPERTIES LABELS "render;long" TIMEOUT 900 ENVIRONMENT "${AEROCAL_REPORT_OUTPUTS_ENV}")
add_test(NAME tools/render_pdf
  COMMAND ${AEROCAL_PYTHON3} -m unittest -v render_test
  WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(tools/render_pdf PROPERTIES LABELS "render;cli" TIMEOUT 600
  ENVIRONMENT "${AEROCAL_REPORT_OUTPUTS_ENV};AEROCAL_RENDER_PARTS=pdf")
