aerocal_add_test(tools/cli_simulate LIBS aerocal::triangulation LABELS cli)
