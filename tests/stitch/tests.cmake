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
