# Stitching: adjustment, model choice, flight stability, result JSON, resampling, CLI.
aerocal_add_test(stitch/stitch_adjustment LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/match_real LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/model_selection LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/flight_stability LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/match_lsm LIBS aerocal::stitch LABELS unit)
aerocal_add_test(stitch/virtual_image LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/tiff_raster LIBS aerocal::stitch LABELS unit)
aerocal_add_test(stitch/match_stitch LIBS aerocal::stitch LABELS cli)
aerocal_add_test(stitch/stitch_cli LIBS aerocal::stitch LABELS cli)
# Multi-head rigs: conversion to the virtual image, its error analysis, the rig command.
aerocal_add_test(stitch/rig_conversion LIBS aerocal::stitch LABELS unit)
aerocal_add_test(stitch/rig_error_analysis LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/rig_cli LIBS aerocal::stitch LABELS cli)
aerocal_add_test(stitch/rig_convert LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/rig_design LIBS aerocal::stitch LABELS unit)
aerocal_add_test(stitch/rig_self_calibration LIBS aerocal::triangulation LABELS synthetic)
aerocal_add_test(stitch/rig_self_calibration_study LIBS aerocal::triangulation LABELS long TIMEOUT 1200)
# Rendered head images and the stitched level image of a rig exposure (issue 16 items 1 and 6).
aerocal_add_test(stitch/rig_stitched_image LIBS aerocal::triangulation LABELS synthetic)
aerocal_add_test(stitch/rig_images_cli LIBS aerocal::stitch LABELS cli)
# Image quality (issue 36): slanted-edge e-SFR on exactly rendered edges.
aerocal_add_test(stitch/slanted_edge LIBS aerocal::stitch LABELS synthetic)
# Bar targets: contrast transfer per frequency and the limiting frequency (issue 36 item 2).
aerocal_add_test(stitch/bar_target LIBS aerocal::stitch LABELS synthetic)
aerocal_add_test(stitch/siemens_star LIBS aerocal::stitch LABELS synthetic)
# On images we did not make (tests/data/quality/PROVENANCE.md): a third-party synthetic edge and a
# real satellite image of the Baotou edge target with a published MTF50.
aerocal_add_test(stitch/slanted_edge_real LIBS aerocal::stitch LABELS golden)
# The virtual image's MTF after resampling against the raw sub-image's (issue 36 item 3).
aerocal_add_test(stitch/resampling_mtf LIBS aerocal::stitch LABELS synthetic)
# Edge targets on the ground found in the image from the orientation (issue 36 item 1).
aerocal_add_test(stitch/edge_targets LIBS aerocal::stitch LABELS unit)
# A frame's run as lossless JSON (`aerocal batch` units to the merge, issue 35).
aerocal_add_test(stitch/frame_run_json LIBS aerocal::stitch LABELS unit)
aerocal_add_test(stitch/fast_resample LIBS aerocal::stitch LABELS synthetic)
