aerocal_add_test(triangulation/joint_adjustment LIBS aerocal::triangulation LABELS synthetic TIMEOUT 600)
