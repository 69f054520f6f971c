aerocal_add_test(calib/brown_fraser10 LIBS aerocal::calib LABELS unit)
aerocal_add_test(calib/camera_io LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/subimage_mapping LIBS aerocal::calib LABELS unit)
aerocal_add_test(calib/residuals LIBS aerocal::residual_factories LABELS unit)
aerocal_add_test(calib/problem_builder LIBS aerocal::calib LABELS synthetic)
aerocal_add_test(calib/mounted_block LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/csv LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/data_snooping LIBS aerocal::calib LABELS unit)
aerocal_add_test(calib/normal_equations LIBS aerocal::calib LABELS unit)
aerocal_add_test(calib/camera_model LIBS aerocal::calib LABELS unit)
aerocal_add_test(calib/convert_camera LIBS aerocal::calib LABELS unit)
aerocal_add_test(calib/core LIBS aerocal::calib LABELS unit reader)
# Schemas of the result documents (docs/schema): cross-file references, every kind, findings.
aerocal_add_test(calib/json_schema LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/file_digest LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/rig LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/camera_formats LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/camera_file_variants LIBS aerocal::calib LABELS unit reader)
# Issue 37 class 4: a nan or an empty number in any reader's example is refused or unused.
aerocal_add_test(calib/camera_formats_substitution LIBS aerocal::calib LABELS unit reader)
# Issue 37 class 5: names and ids with line breaks and punctuation through our YAML writers.
aerocal_add_test(calib/hostile_text LIBS aerocal::calib LABELS unit reader)
aerocal_add_test(calib/rotation LIBS aerocal::calib LABELS unit)
# Direction observations of a laboratory calibration (collimator, goniometer; issue 36 item 6).
aerocal_add_test(calib/direction_residual LIBS aerocal::residual_factories LABELS unit)
# Image metadata: JPEG / TIFF / EXIF / XMP by namespace URI (issues 34, 37).
aerocal_add_test(calib/image_metadata LIBS aerocal::calib LABELS unit reader)
