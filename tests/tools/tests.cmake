aerocal_add_test(tools/cli_simulate LIBS aerocal::triangulation LABELS cli)
# `aerocal rig stitch` (issue 16) on a simulated uav4 line.
aerocal_add_test(tools/cli_rig_stitch LIBS aerocal::calib LABELS cli)
aerocal_add_test(tools/cli_flight LIBS aerocal::stitch LABELS cli TIMEOUT 600)
target_sources(test_tools_cli_flight PRIVATE ${PROJECT_SOURCE_DIR}/tools/observation_tables.cc)
# The report script the tests run on a flight's output (AEROCAL_REPORT_SCRIPT, as the program's).
target_compile_definitions(test_tools_cli_flight PRIVATE ${AEROCAL_TOOL_DEFINITIONS})
include(${CMAKE_CURRENT_SOURCE_DIR}/tools/report.cmake)
include(${CMAKE_CURRENT_SOURCE_DIR}/tools/report_outputs.cmake)
aerocal_add_test(tools/bad_input LIBS aerocal::triangulation LABELS cli)
aerocal_add_test(tools/cli_joint LIBS aerocal::calib LABELS cli TIMEOUT 600)
aerocal_add_test(tools/cli_options LIBS aerocal::calib LABELS cli)
# Camera files in other tools' formats (issue 15): the CLI, plus the OpenCV FileStorage format
# (tools/camera_formats.cc) against cv::projectPoints and cv::undistortPoints.
aerocal_add_test(tools/cli_camera LIBS aerocal::calib ${AEROCAL_OPENCV_LIBS} LABELS cli)
target_sources(test_tools_cli_camera PRIVATE ${PROJECT_SOURCE_DIR}/tools/camera_formats.cc
  ${PROJECT_SOURCE_DIR}/tools/opencv_storage_scan.cc)
target_include_directories(test_tools_cli_camera PRIVATE ${OpenCV_INCLUDE_DIRS})
aerocal_add_test(tools/cli_calibrate LIBS aerocal::calib LABELS cli)
# Result documents: kind and schema_version of every command, readers refusing others.
aerocal_add_test(tools/cli_results LIBS aerocal::calib LABELS cli)
aerocal_add_test(tools/cli_camera_models LIBS aerocal::calib LABELS cli)
# `aerocal quality mtf` (issue 36) on rendered edges written as 8- and 16-bit images.
aerocal_add_test(tools/cli_quality LIBS aerocal::stitch LABELS cli)
# Issue 36 item 6: calibrate --directions (collimator array, goniometer, groups, bad rows).
aerocal_add_test(tools/cli_directions LIBS aerocal::triangulation LABELS cli)
# Issue 37 (bad input, part 2): schema-checked certificate inputs, budget units, absurd geometry,
# bounded sizes, the renderer's text and output sets, the ranges of every numeric option.
aerocal_add_test(tools/bad_input2 LIBS aerocal::triangulation LABELS cli TIMEOUT 900)
# Plausibility before solving (issue 33 item 5): ';' CSVs, another tool's camera file, pixels off
# the format, c given in pixels; the global --verbose / --quiet after the command (item 4).
aerocal_add_test(tools/cli_plausibility LIBS aerocal::calib LABELS cli)
# Issue 37, part 3: OpenCV FileStorage bounds and lines, --camera on files of one camera, camera
# convert's outputs as a set, size products of options.
aerocal_add_test(tools/bad_input3 LIBS aerocal::calib LABELS cli)
aerocal_add_test(tools/output_set LIBS aerocal::calib LABELS unit reader)
target_sources(test_tools_output_set PRIVATE ${PROJECT_SOURCE_DIR}/tools/output_set.cc)
# `aerocal batch` (issue 35): plan / run --shard / status / merge against `flight`, a killed run,
# changed and failing units, GNU Parallel (skipped without it), the Slurm scripts.
aerocal_add_test(tools/cli_batch LIBS aerocal::calib LABELS cli)
target_sources(test_tools_cli_batch PRIVATE ${PROJECT_SOURCE_DIR}/tools/observation_tables.cc)
# The same for real under Slurm: munged, slurmctld and slurmd started on this machine
# (tests/tools/slurm_localhost.sh), a 4-task job array and the dependent merge. Skipped with the
# reason without slurm-wlm and munge (not in tools/setup.sh); label long: it starts daemons.
aerocal_add_test(tools/cli_batch_slurm LIBS aerocal::calib LABELS long TIMEOUT 900)
aerocal_add_test(tools/cli_vocabulary LABELS cli)
# The numeric options' validators (FiniteRange, SeedCheck) on every kind of value, in process.
aerocal_add_test(tools/option_ranges LIBS aerocal::calib LABELS unit)
