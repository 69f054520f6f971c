aerocal_add_test(tools/cli_simulate LIBS aerocal::triangulation LABELS cli)
aerocal_add_test(tools/cli_flight LIBS aerocal::calib LABELS cli TIMEOUT 600)
include(${CMAKE_CURRENT_SOURCE_DIR}/tools/report.cmake)
aerocal_add_test(tools/cli_joint LIBS aerocal::calib LABELS cli TIMEOUT 600)
