aerocal_add_test(triangulation/block_adjustment LIBS aerocal::triangulation LABELS synthetic)
aerocal_add_test(triangulation/monte_carlo LIBS aerocal::triangulation LABELS synthetic)
aerocal_add_test(triangulation/forward_intersection LIBS aerocal::triangulation LABELS unit)
