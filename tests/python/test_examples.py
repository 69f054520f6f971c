"""The examples/ scripts run as a user runs them, and print what the module computes (issue 32).

Each script is run with this interpreter on simulated flights made by `aerocal simulate`; its
printed numbers (repr of the doubles) are compared with the module's own results on the same
inputs, so a script that mis-reads a result fails here.
"""

import csv
import os
import subprocess
import sys
import tempfile

import numpy as np
import pytest

import aerocal

BINARY = os.environ["AEROCAL_BINARY"]
EXAMPLES = os.path.join(os.environ["AEROCAL_SOURCE_DIR"], "examples")


def script(name, *args, cwd=None):
    done = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args],
                          capture_output=True, text=True, cwd=cwd)
    return done.returncode, done.stdout, done.stderr


@pytest.fixture(scope="module")
def flights():
    with tempfile.TemporaryDirectory(prefix="aerocal_examples_") as tmp:
        paths = []
        for seed in ("1", "2"):
            out = os.path.join(tmp, f"flight{seed}")
            done = subprocess.run([BINARY, "simulate", "--out", out, "--seed", seed],
                                  capture_output=True, text=True)
            assert done.returncode == 0, done.stderr
            paths.append(os.path.join(out, "project.yaml"))
        yield tmp, paths


def test_calibrate_flight_prints_the_adjustment_and_draws_the_field(flights):
    tmp, paths = flights
    plot = os.path.join(tmp, "field.png")
    code, out, err = script("calibrate_flight.py", paths[0], "--self-calibration", "all",
                            "--plot", plot)
    assert code == 0, err
    r = aerocal.adjust(aerocal.Block.read(paths[0]), self_calibration="all")
    assert f"sigma0 {r.sigma0!r}" in out
    assert f"camera cam1 c {r.cameras[0].estimated['c']!r} +- {r.cameras[0].sigma['c']!r}" in out
    with open(plot, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert "stage" in err  # the progress callback drew its stages


def test_calibrate_flight_bad_project_is_exit_2():
    code, _, err = script("calibrate_flight.py", "/nonexistent/project.yaml")
    assert code == 2 and "/nonexistent/project.yaml" in err


def test_tabulate_flights_equals_the_module_per_flight(flights):
    tmp, paths = flights
    table = os.path.join(tmp, "table.csv")
    code, _, err = script("tabulate_flights.py", *paths, "--csv", table)
    assert code == 0, err
    with open(table) as f:
        rows = list(csv.DictReader(f))
    assert [row["project"] for row in rows] == paths
    for row, path in zip(rows, paths):
        r = aerocal.adjust(aerocal.Block.read(path), self_calibration="all")
        for name in ("c", "x0", "y0", "K1"):
            assert float(row[name]) == r.cameras[0].estimated[name]
            assert float(row[f"s_{name}"]) == r.cameras[0].sigma[name]
        assert float(row["check_rmse_Z_m"]) == r.check_rmse_m[2]
    # Two flights of the same camera: different noise, the same camera within their sigmas.
    c = [float(row["c"]) for row in rows]
    s = [float(row["s_c"]) for row in rows]
    assert abs(c[0] - c[1]) < 3 * np.hypot(*s)


def test_convert_camera_undistorts_through_the_rays(flights):
    tmp, _ = flights
    nominal = os.path.join(tmp, "flight1", "camera_nominal.yaml")
    metashape = os.path.join(tmp, "camera_metashape.xml")
    in_metashape, residual = aerocal.convert_camera(aerocal.Camera.read(nominal),
                                                    model="metashape_frame")
    assert residual["max_px"] < 0.01
    in_metashape.write(metashape, format="metashape")
    out_file = os.path.join(tmp, "converted.yaml")
    code, out, err = script("convert_camera.py", metashape, "--out", out_file)
    assert code == 0, err
    camera = aerocal.Camera.read(metashape)
    centre = np.array([[(camera.width - 1) / 2.0, (camera.height - 1) / 2.0]])
    ray = camera.image_to_ray(centre)[0]
    principal = camera.ray_to_image(np.zeros((1, 2)))[0]
    c_px = camera.principal_distance_px
    expected = (principal[0] + c_px * ray[0], principal[1] - c_px * ray[1])
    assert f"-> {expected[0]!r} {expected[1]!r}" in out
    converted = aerocal.Camera.read(out_file)
    assert converted.model == "brown_fraser_10"
