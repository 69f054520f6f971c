"""The Python module against the command line on the same inputs (issue 32).

Run by ctest (tests/python/python.cmake) with PYTHONPATH at the build tree's package and
AEROCAL_BINARY at the command; the simulated flight is made by `aerocal simulate`, so nothing here
is a second implementation: every number compared comes from both sides of the same library.
"""

import csv
import json
import math
import os
import subprocess
import tempfile

import numpy as np
import pytest

import aerocal

BINARY = os.environ["AEROCAL_BINARY"]
SOURCE = os.environ["AEROCAL_SOURCE_DIR"]
SHARED = os.path.join(SOURCE, "..", "shared", "data")


def run(*args):
    done = subprocess.run([BINARY, *args], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


@pytest.fixture(scope="module")
def flight():
    with tempfile.TemporaryDirectory(prefix="aerocal_py_") as tmp:
        code, out = run("simulate", "--out", os.path.join(tmp, "flight"))
        assert code == 0, out
        yield tmp


def test_the_calls_of_the_issue_work_exactly_so(flight):
    p = os.path.join(flight, "flight", "project.yaml")
    b = aerocal.Block.read(p)
    r = aerocal.adjust(b, self_calibration="all")
    assert r.sigma0 > 0 and isinstance(r.valid, bool)
    assert r.check_rmse_m.shape == (3,)
    c = r.cameras[0].estimated["c"]
    s = r.cameras[0].sigma["c"]
    assert c > 0 and s > 0
    assert r.correlation.shape == (10, 10)
    np.testing.assert_allclose(np.diag(r.correlation), 1.0, atol=1e-12)
    cam = aerocal.Camera.read(os.path.join(flight, "flight", "camera_nominal.yaml"), format="auto")
    c2, res = aerocal.convert_camera(cam, model="brown_fraser_10")
    assert res["exact"] and res["max_px"] < 1e-9
    rays = cam.image_to_ray(np.array([[0.0, 0.0]]))
    assert rays.shape == (1, 2)


def test_adjust_equals_the_command_to_the_last_digit(flight):
    p = os.path.join(flight, "flight", "project.yaml")
    out = os.path.join(flight, "cli.json")
    code, text = run("adjust", "--project", p, "--self-calibration", "all", "--out", out)
    assert code == 0, text
    r = aerocal.adjust(aerocal.Block.read(p), self_calibration="all")
    with open(out) as f:
        cli = f.read()
    # The same document (timings aside: they are the clock's, not the adjustment's).
    a, b = json.loads(cli), json.loads(r.to_json())
    for doc in (a, b):
        doc.pop("timing", None)
        doc.pop("seconds", None)
        doc["snooping"].pop("seconds_testing", None)
    assert a == b
    assert b["cameras"][0]["estimated"]["c"] == r.cameras[0].estimated["c"]


def test_residuals_and_redundancy_are_arrays(flight):
    r = aerocal.adjust(aerocal.Block.read(os.path.join(flight, "flight")), self_calibration="all")
    res = r.residuals
    n = len(res["image"])
    assert res["residual_px"].shape == (n, 2) and res["used"].shape == (n,)
    used = res["used"]
    # The image residuals of a consistent adjustment: RMS at the simulated 0.2 px noise.
    rms = math.sqrt(np.mean(res["residual_px"][used] ** 2))
    assert 0.1 < rms < 0.3
    assert np.nanmax(res["redundancy"]) <= 1.0


def test_image_to_ray_and_back_are_inverse(flight):
    cam = aerocal.Camera.read(os.path.join(flight, "flight", "camera_truth.yaml"))
    cam.set_param("K1", -5e-6)
    cols, rows = np.meshgrid(np.linspace(0, cam.width - 1, 7), np.linspace(0, cam.height - 1, 5))
    pixels = np.column_stack([cols.ravel(), rows.ravel()])
    back = cam.ray_to_image(cam.image_to_ray(pixels))
    np.testing.assert_allclose(back, pixels, atol=1e-6)
    # The principal point's ray is the axis.
    assert cam.params["x0"] != 0 or cam.params["y0"] != 0


def test_block_from_arrays_equals_the_files(flight):
    folder = os.path.join(flight, "flight")
    files = aerocal.Block.read(os.path.join(folder, "project.yaml"))
    cam = aerocal.Camera.read(os.path.join(folder, "camera_nominal.yaml"))
    e, o, p = files.exposures, files.observations, files.points
    exposures = {"image": e["image"], "camera": e["camera"],
                 "X": e["center_m"][:, 0], "Y": e["center_m"][:, 1], "Z": e["center_m"][:, 2],
                 "omega": e["opk_deg"][:, 0], "phi": e["opk_deg"][:, 1], "kappa": e["opk_deg"][:, 2]}
    import csv
    with open(os.path.join(folder, "points.csv")) as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    def number(text):
        return float(text) if text.strip() else float("nan")  # an empty field: absent
    points = {k: [number(r[k]) if k not in ("point", "role") else r[k] for r in rows]
              for k in ("point", "X", "Y", "Z", "sX", "sY", "sZ", "role")}
    observations = {"image": o["image"], "point": o["point"], "col": o["pixel"][:, 0],
                    "row": o["pixel"][:, 1], "sigma_px": o["sigma_px"]}
    arrays = aerocal.Block.from_arrays({"cam1": cam}, exposures, points, observations)
    a = aerocal.adjust(arrays)
    b = aerocal.adjust(files)
    assert a.sigma0 == pytest.approx(b.sigma0, rel=1e-9)
    np.testing.assert_allclose(a.check_rmse_m, b.check_rmse_m, rtol=1e-9)


def test_errors_are_value_errors_with_file_and_line(flight):
    bad = os.path.join(flight, "bad.csv")
    with open(bad, "w") as f:
        f.write("not a camera\n")
    with pytest.raises(ValueError):
        aerocal.Camera.read(bad, format="colmap")
    proj = os.path.join(flight, "flight")
    with open(os.path.join(proj, "points.csv")) as f:
        text = f.read()
    broken = os.path.join(flight, "broken")
    subprocess.run(["cp", "-r", proj, broken], check=True)
    with open(os.path.join(broken, "points.csv"), "w") as f:
        f.write(text.replace("control", "kontrol", 1))
    with pytest.raises(aerocal.InputError, match=r"points\.csv:\d+:"):
        aerocal.Block.read(broken)
    with pytest.raises(TypeError, match="unknown option"):
        aerocal.adjust(aerocal.Block.read(proj), no_such_option=1)


def test_convert_a_dji_camera_from_the_documented_records(tmp_path):
    # Record A of the documented DewarpData examples (a Phantom 4 RTK, 5472 x 3648), written as
    # exiftool prints the value: the date, then fx,fy,cx,cy,k1,k2,p1,p2,k3 on one line.
    path = os.path.join(SHARED, "dji_dewarpdata_documented", "dewarpdata_examples.txt")
    if not os.path.exists(path):
        pytest.skip("../shared/data/dji_dewarpdata_documented is absent")
    with open(path) as f:
        record = next(line for line in f if line.startswith("A |"))
    value = record.rsplit("|", 1)[1].strip()
    dewarp = tmp_path / "dewarp.txt"
    dewarp.write_text(value + "\n")
    names = aerocal.formats()
    assert "dji" in names and "opencv" in names
    cam = aerocal.Camera.read(str(dewarp), format="dji", width=5472, height=3648)
    fx = float(value.split(";")[1].split(",")[0])
    assert cam.width == 5472 and cam.height == 3648
    ours, res = aerocal.convert_camera(cam, model="brown_fraser_10")
    assert ours.model == "brown_fraser_10"
    # k1 = -0.26 on a 1-inch sensor: the 10-parameter model fits it to about a pixel inside 80 % of
    # the half-diagonal (14 px at the extreme corner, where the two models' series part).
    assert res["rms_px"] < 2.0 and res["max_inner80_px"] < 3.0, res["summary"]
    # The principal distance survives the conversion within 1 % (the fit trades c against K1).
    assert ours.principal_distance_mm == pytest.approx(cam.principal_distance_mm, rel=1e-2)
    assert fx > 3000


def test_help_names_every_area():
    text = aerocal.__doc__
    for word in ("Camera.read", "convert_camera", "Block.read", "adjust(", "InputError"):
        assert word in text


def test_progress_callback_counts_the_stages_and_can_stop_the_work(flight):
    p = os.path.join(flight, "flight", "project.yaml")
    seen = []
    r = aerocal.adjust(aerocal.Block.read(p), self_calibration="all",
                       progress=lambda done, total: seen.append((done, total)))
    assert r.converged and seen
    done = [d for d, _ in seen]
    assert done == sorted(done) and len({t for _, t in seen}) == 1
    assert done[-1] == seen[-1][1]  # the bar completes

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop(f"{done}/{total}")

    with pytest.raises(Stop):
        aerocal.adjust(aerocal.Block.read(p), self_calibration="all", progress=stop)
    with pytest.raises(TypeError):
        aerocal.adjust(aerocal.Block.read(p), progress=3)
    seen_auto = []
    aerocal.adjust(aerocal.Block.read(p), self_calibration="auto",
                   progress=lambda d, t: seen_auto.append((d, t)))
    assert seen_auto[-1][0] == seen_auto[-1][1] == 11  # ten candidates + the final round


def test_covariance_is_the_sigmas_around_the_correlation(flight):
    r = aerocal.adjust(aerocal.Block.read(os.path.join(flight, "flight")), self_calibration="all")
    names = r.correlation_names
    cov = r.covariance(["camera cam1"])
    assert cov.shape == (10, 10)
    s = np.array([r.cameras[0].sigma[n.split(".", 1)[1]] for n in names])
    np.testing.assert_allclose(np.diag(cov), s ** 2, rtol=1e-12)
    np.testing.assert_allclose(cov / np.outer(s, s), r.correlation, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(cov, cov.T, rtol=0, atol=0)
    # A covariance matrix is positive semi-definite (relative to its scale, per entry).
    scaled = cov / np.outer(s, s)
    assert np.linalg.eigvalsh(scaled).min() > -1e-9
    sub = r.covariance(["camera cam1.K1", "camera cam1.c"])
    assert sub[0, 0] == cov[3, 3] and sub[1, 1] == cov[0, 0] and sub[0, 1] == cov[3, 0]
    with pytest.raises(ValueError, match="camera nope"):
        r.covariance(["camera nope"])


def test_covariance_of_exposures_and_points_on_the_example_flight(flight):
    """(a) an exposure's diagonal squares to the result file's sigmas; (b) the joint matrix with
    the interior, two exposures and a point is symmetric positive semi-definite, its interior
    block the interior covariance of the run; (d) names the result does not hold raise."""
    r = aerocal.adjust(aerocal.Block.read(os.path.join(flight, "flight")), self_calibration="all")
    doc = json.loads(r.to_json())
    used = [e for e in doc["exposures"] if e["used"]]
    first, last = used[0], used[-1]
    keys = ("X", "Y", "Z", "omega", "phi", "kappa")
    for e in (first, last):
        cov = r.covariance(["exposure " + e["image"]])
        assert cov.shape == (6, 6)
        # The run took its covariance from the solver's reduced system at the solution, this
        # call from a fresh evaluation of the same Jacobian: equal to the rounding, which the
        # c ~ Z0 correlation of a fully self-calibrating flight amplifies to ~1e-9 (measured 7e-10).
        np.testing.assert_allclose(np.sqrt(np.diag(cov)), [e["sigma"][k] for k in keys],
                                   rtol=1e-8, atol=0)
    table = r.exposures
    i = table["image"].index(first["image"])
    np.testing.assert_allclose(table["sigma_center_m"][i], [first["sigma"][k] for k in keys[:3]],
                               rtol=1e-15)
    np.testing.assert_allclose(table["center_m"][i], [first[k] for k in keys[:3]], rtol=1e-15)
    point = r.points["point"][0]
    names = ["camera cam1", "exposure " + first["image"], "exposure " + last["image"],
             "point " + point]
    joint = r.covariance(names)
    assert joint.shape == (10 + 6 + 6 + 3, 10 + 6 + 6 + 3)
    np.testing.assert_array_equal(joint, joint.T)
    s = np.sqrt(np.diag(joint))
    assert np.all(s > 0)
    assert np.linalg.eigvalsh(joint / np.outer(s, s)).min() > -1e-9
    interior = r.covariance(["camera cam1"])
    si = np.sqrt(np.diag(interior))
    assert np.abs((joint[:10, :10] - interior) / np.outer(si, si)).max() < 1e-8  # 1.4e-9 measured
    # The block's first and last exposure share no point: their cross block is computed, not 0.
    cross = joint[10:16, 16:22] / np.outer(s[10:16], s[16:22])
    assert np.abs(cross).max() > 1e-3
    # The same entries asked in another order are the same numbers.
    swapped = r.covariance(["point " + point, "exposure " + first["image"]])
    np.testing.assert_allclose(swapped[3:, :3], joint[10:16, 22:25], rtol=1e-10, atol=0)
    for bad in ("exposure nope", "point nope", "camera cam1.Q9", "cam1"):
        with pytest.raises(ValueError, match=bad):
            r.covariance(["exposure " + first["image"], bad])


def _rotation(opk):
    """R = Rx(omega) Ry(phi) Rz(kappa) per row of opk (rad), CONVENTIONS.md section 4."""
    o, p, k = opk[:, 0], opk[:, 1], opk[:, 2]
    one, zero = np.ones_like(o), np.zeros_like(o)
    rx = np.stack([one, zero, zero, zero, np.cos(o), -np.sin(o), zero, np.sin(o), np.cos(o)], 1)
    ry = np.stack([np.cos(p), zero, np.sin(p), zero, one, zero, -np.sin(p), zero, np.cos(p)], 1)
    rz = np.stack([np.cos(k), -np.sin(k), zero, np.sin(k), np.cos(k), zero, zero, zero, one], 1)
    return (rx.reshape(-1, 3, 3) @ ry.reshape(-1, 3, 3)) @ rz.reshape(-1, 3, 3)


def test_covariance_cross_blocks_equal_the_inverse_normal_matrix(tmp_path):
    """(c) The oracle: a block of two strips of 28 exposures built from arrays (more than 300
    reduced parameters: the sparse selected inverse), its normal matrix J^T J formed here from a
    numerical Jacobian of the collinearity equations and the control points' weights, inverted
    densely and scaled by sigma0^2, against covariance() of two exposures that share no point, a
    tie point and c."""
    rng = np.random.default_rng(7)
    path = tmp_path / "camera.yaml"
    path.write_text("name: oracle\nmodel: brown_fraser_10\npixel_size_mm: 0.01\n"
                    "format_px: [1000, 800]\ninterior: {c: 50}\n")
    cam = aerocal.Camera.read(str(path))
    n_strip, base_m, height_m, sigma_px, pixel_mm = 28, 25.0, 500.0, 0.3, 0.01
    centers = np.array([[i * base_m, 50.0 * s, height_m] for s in range(2) for i in range(n_strip)])
    centers += rng.normal(0, 2.0, centers.shape)
    opk = np.radians(rng.normal(0, 1.0, centers.shape))
    gx, gy = np.meshgrid(np.arange(-40, n_strip * base_m + 40, 20.0), np.arange(-30, 81, 20.0))
    truth = np.column_stack([gx.ravel(), gy.ravel(), rng.uniform(0, 30, gx.size)])
    rot = _rotation(opk)
    images, points, pixels = [], [], []
    for e in range(len(centers)):
        uvw = (truth - centers[e]) @ rot[e]  # R^T (X - X0) per row
        px = cam.ray_to_image(-uvw[:, :2] / uvw[:, 2:])
        inside = (px[:, 0] > 5) & (px[:, 0] < 995) & (px[:, 1] > 5) & (px[:, 1] < 795)
        for p in np.flatnonzero(inside):
            images.append(e), points.append(p), pixels.append(px[p])
    images, points = np.array(images), np.array(points)
    pixels = np.array(pixels) + rng.normal(0, sigma_px, (len(images), 2))
    seen = np.bincount(points, minlength=len(truth)) >= 2
    keep = seen[points]
    images, points, pixels = images[keep], points[keep], pixels[keep]
    ids = ["P%03d" % p for p in range(len(truth))]
    control = [p for p in np.flatnonzero(seen) if p % 7 == 0]
    exposures = {"image": ["E%02d" % e for e in range(len(centers))],
                 "camera": ["cam1"] * len(centers)}
    start = centers + rng.normal(0, 1.0, centers.shape)
    for k, key in enumerate("XYZ"):
        exposures[key] = start[:, k]
    for k, key in enumerate(("omega", "phi", "kappa")):
        exposures[key] = np.degrees(opk[:, k]) + 0.05
    survey = truth + rng.normal(0, 0.03, truth.shape)
    nan = float("nan")
    table = {"point": [ids[p] for p in np.flatnonzero(seen)],
             "role": ["control" if p in control else "tie" for p in np.flatnonzero(seen)]}
    for k, key in enumerate("XYZ"):
        table[key] = [survey[p, k] if p in control else nan for p in np.flatnonzero(seen)]
        table["s" + key] = [0.03 if p in control else nan for p in np.flatnonzero(seen)]
    observations = {"image": [exposures["image"][e] for e in images],
                    "point": [ids[p] for p in points], "col": pixels[:, 0], "row": pixels[:, 1],
                    "sigma_px": np.full(len(images), sigma_px)}
    block = aerocal.Block.from_arrays({"cam1": cam}, exposures, table, observations)
    r = aerocal.adjust(block, self_calibration="c", no_snooping=True, no_interior_sigma=True)
    assert r.converged and r.residuals["used"].all()
    method = json.loads(r.to_json())["determinability"]["covariance_method"]
    assert method == "schur_selected_inverse"  # the sparse path, where pairs can miss the pattern

    # The oracle's unknowns at the adjustment's solution: centres, angles (rad), points, c.
    adjusted = r.exposures
    C = adjusted["center_m"].copy()
    A = np.radians(adjusted["opk_deg"])
    order = {p: i for i, p in enumerate(r.points["point"])}
    P = r.points["xyz_m"].copy()
    pidx = np.array([order[ids[p]] for p in points])
    c = r.cameras[0].estimated["c"]
    cam.set_param("c", c)
    ideal = c * cam.image_to_ray(pixels)  # the measured photo coordinates, corrected (mm)
    ctrl = np.array([order[ids[p]] for p in control])
    ctrl_survey = survey[control]
    sigma_mm = sigma_px * pixel_mm

    def residuals(C, A, P, c):
        uvw = np.einsum("nji,nj->ni", _rotation(A)[images], P[pidx] - C[images])
        image = (ideal + c * uvw[:, :2] / uvw[:, 2:]) / sigma_mm
        return np.concatenate([image.ravel(), ((P[ctrl] - ctrl_survey) / 0.03).ravel()])

    v = residuals(C, A, P, c)
    ne, npt = len(C), len(P)
    n_unknowns = 6 * ne + 3 * npt + 1
    # The same model as the adjustment's: its residuals and sigma0.
    res = r.residuals
    by_ray = {(i, p): x for i, p, x in zip(res["image"], res["point"], res["residual_px"])}
    theirs = np.array([by_ray[exposures["image"][e], ids[p]] for e, p in zip(images, points)])
    np.testing.assert_allclose(v[:2 * len(images)].reshape(-1, 2) * sigma_px * [1, -1], theirs,
                               atol=1e-6)
    assert math.sqrt(v @ v / (len(v) - n_unknowns)) == pytest.approx(r.sigma0, rel=1e-6)
    # Numerical Jacobian: every row depends on one exposure and one point, so one component of
    # all exposures (points) moved at once gives each row's derivative by its own block.
    J = np.zeros((len(v), n_unknowns))
    image_rows = np.repeat(np.arange(len(images)) * 2, 2) + np.tile([0, 1], len(images))
    rows_e = np.repeat(images, 2)
    rows_p = np.concatenate([np.repeat(pidx, 2), np.repeat(ctrl, 3)])
    all_rows = np.arange(len(v))
    for k in range(3):
        for offset, h, which in ((0, 1e-4, "C"), (3 * ne, 1e-6, "A"), (6 * ne, 1e-4, "P")):
            plus, minus = [C.copy(), A.copy(), P.copy()], [C.copy(), A.copy(), P.copy()]
            i = "CAP".index(which)
            plus[i][:, k] += h
            minus[i][:, k] -= h
            d = (residuals(*plus, c) - residuals(*minus, c)) / (2 * h)
            if which == "P":
                J[all_rows, offset + 3 * rows_p + k] = d
            else:
                J[image_rows, offset + 3 * rows_e + k] = d[image_rows]
    J[:, -1] = (residuals(C, A, P, c + 1e-5) - residuals(C, A, P, c - 1e-5)) / 2e-5
    Q = r.sigma0 ** 2 * np.linalg.inv(J.T @ J)
    far = (0, 2 * n_strip - 1)  # strip 1's first and strip 2's last exposure: no common point
    assert not set(pidx[images == far[0]]) & set(pidx[images == far[1]])
    tie = r.points["point"].index(ids[next(p for p in np.flatnonzero(seen) if p not in control)])
    index = []
    for e in far:
        index += [3 * e + k for k in range(3)] + [3 * ne + 3 * e + k for k in range(3)]
    index += [6 * ne + 3 * tie + k for k in range(3)] + [n_unknowns - 1]
    scale = np.array([1, 1, 1] + [180 / math.pi] * 3 + [1, 1, 1] + [180 / math.pi] * 3 +
                     [1, 1, 1, 1])
    expected = Q[np.ix_(index, index)] * np.outer(scale, scale)
    got = r.covariance(["exposure E%02d" % far[0], "exposure E%02d" % far[1],
                        "point " + r.points["point"][tie], "camera cam1.c"])
    s = np.sqrt(np.diag(expected))
    assert np.abs((got - expected) / np.outer(s, s)).max() < 1e-7  # 4.5e-9 measured
    assert np.abs(expected[:6, 6:12] / np.outer(s[:6], s[6:12])).max() > 1e-3  # not a zero block


def test_stitch_equals_the_command_and_types_its_result(flight):
    camera = os.path.join(flight, "flight", "camera_nominal.yaml")
    obs = os.path.join(flight, "flight", "stitch_obs.csv")
    out = os.path.join(flight, "stitch.json")
    code, text = run("stitch", "--camera", camera, "--obs", obs, "--base", "III,IV", "--out", out)
    assert code == 0, text
    seen = []
    r = aerocal.stitch(camera, obs, base="III,IV", progress=lambda d, t: seen.append((d, t)))
    with open(out) as f:
        cli = json.load(f)
    doc = json.loads(r.to_json())
    for d in (cli, doc):
        d.pop("seconds", None)
        d.pop("timing", None)
    assert doc == cli
    assert r.converged and len(r.frames) == cli["n_frames"] == seen[-1][1] == seen[-1][0]
    frame = r.frames[0]
    for sid in ("III", "IV"):  # the datum: held, so no sigma (None, never 0)
        assert frame["subimages"][sid]["base"] and frame["subimages"][sid]["sigma"] is None
    free = [s for s in frame["subimages"].values() if not s["base"]]
    assert free
    for s in free:
        n = s["params"].shape[0]
        assert s["covariance"].shape == (n, n)
        np.testing.assert_allclose(np.sqrt(np.diag(s["covariance"])), s["sigma"], rtol=1e-9)
    with pytest.raises(ValueError, match="model"):
        aerocal.stitch(camera, obs, model="bilinear")
    with pytest.raises(ValueError, match="nope.csv"):
        aerocal.stitch(camera, os.path.join(flight, "nope.csv"))


def test_a_real_block_equals_the_command_to_the_last_digit(tmp_path):
    """The ODM UAV block (10 real images, GCPs surveyed by GNSS): the module's result file is the
    command's, with the options a user of that block needs (robust start: two gross blunders)."""
    data = os.path.join(SHARED, "odm_br_uav_gcp_block", "odm_gcp_br")
    if not os.path.isdir(data):
        pytest.skip("../shared/data/odm_br_uav_gcp_block is absent")
    camera = tmp_path / "sx260.yaml"
    camera.write_text("name: Canon PowerShot SX260 HS\npixel_size_mm: 0.00154959\n"
                      "format_px: [4000, 3000]\ninterior: {c: 4.5}\n")
    block = str(tmp_path / "block")
    code, text = run("import", "odm", "--gcp-list", os.path.join(data, "gcp_list_floatxy_raw.txt"),
                     "--camera", str(camera), "--control", os.path.join(data, "gcp_list_raw.txt"),
                     "--out", block)
    assert code == 0, text
    out = str(tmp_path / "cli.json")
    code, text = run("adjust", "--project", block, "--robust-start", "--self-calibration", "auto",
                     "--out", out)
    assert code in (0, 3), text
    r = aerocal.adjust(aerocal.Block.read(block), self_calibration="auto", robust_start=True)
    with open(out) as f:
        cli = json.load(f)
    doc = json.loads(r.to_json())
    for d in (cli, doc):
        d.pop("timing", None)
        d.pop("seconds", None)
        d["snooping"].pop("seconds_testing", None)
    assert doc == cli
    assert (code == 0) == r.valid


SMALL_CAMERA = """name: small
pixel_size_mm: 0.009
format_px: [400, 300]
interior: {c: 50}
subimages:
  - {id: I, format_px: [210, 160], model: affine, params: [1, 0, 0, 0, 1, 0]}
  - {id: II, format_px: [210, 160], model: affine, params: [1, 0, 190, 0, 1, 0]}
  - {id: III, format_px: [210, 160], model: affine, params: [1, 0, 0, 0, 1, 140]}
  - {id: IV, format_px: [210, 160], model: affine, params: [1, 0, 190, 0, 1, 140]}
"""


def test_resample_equals_the_command(tmp_path):
    from PIL import Image  # Debian's python3-pil (a dependency of python3-matplotlib)
    camera = tmp_path / "camera.yaml"
    camera.write_text(SMALL_CAMERA)
    # The nominal mappings, II turned by 1 mrad and shifted by sub-pixel amounts: bilinear
    # interpolation between textured pixels everywhere in II.
    subimages = []
    for sid, (e, f) in {"I": (0, 0), "II": (190, 0), "III": (0, 140), "IV": (190, 140)}.items():
        p = [1, 0, e, 0, 1, f]
        if sid == "II":
            p = [1, -1e-3, e - 0.37, 1e-3, 1, f + 0.21]
        subimages.append({"id": sid, "model": "affine", "params": p})
    mapping = tmp_path / "r.json"
    mapping.write_text(json.dumps({"kind": "stitch", "schema_version": 2, "subimages": subimages}))
    rng = np.random.default_rng(3)
    images = {}
    for sid in ("I", "II", "III", "IV"):
        path = tmp_path / f"{sid}.png"
        Image.fromarray(rng.integers(0, 256, size=(160, 210), dtype=np.uint8)).save(path)
        images[sid] = str(path)
    text = ",".join(f"{k}={v}" for k, v in images.items())
    cli = tmp_path / "cli.tif"
    code, out = run("resample", "--camera", str(camera), "--mapping", str(mapping), "--images", text,
                    "--fill", "7", "--out", str(cli))
    assert code == 0, out
    py_tif = tmp_path / "py.tif"
    pixels = aerocal.resample(str(camera), str(mapping), images, fill=7, out=str(py_tif))
    assert pixels.dtype == np.uint8 and pixels.shape == (300, 400)
    assert py_tif.read_bytes() == cli.read_bytes()  # the command's file, byte for byte
    np.testing.assert_array_equal(pixels, np.asarray(Image.open(cli)))
    # The option's text gives the same image; the corner II leaves uncovered holds the fill.
    np.testing.assert_array_equal(aerocal.resample(str(camera), str(mapping), text, fill=7), pixels)
    assert pixels[0, 399] == 7
    with pytest.raises(ValueError, match="no image for sub-image II"):
        aerocal.resample(str(camera), str(mapping), {"I": images["I"]})
    with pytest.raises(ValueError, match="--fill"):
        aerocal.resample(str(camera), str(mapping), images, fill=300)


def _without_clock(doc):
    """The document without the clock's keys (seconds, timing, seconds_testing), at any depth."""
    if isinstance(doc, dict):
        return {k: _without_clock(v) for k, v in doc.items() if k not in ("seconds", "timing", "seconds_testing")}
    if isinstance(doc, list):
        return [_without_clock(v) for v in doc]
    return doc


def test_calibrate_equals_the_command(tmp_path):
    field = tmp_path / "tf"
    code, out = run("simulate", "--test-field", "--groups", "2", "--images-per-group", "4",
                    "--seed", "3", "--out", str(field))
    assert code == 0, out
    camera, obs, points, groups = (str(field / f) for f in
                                   ("camera_nominal.yaml", "observations.csv", "points.csv", "groups.csv"))
    cli = tmp_path / "cli.json"
    code, out = run("calibrate", "--camera", camera, "--observations", obs, "--points", points,
                    "--groups", groups, "--write-camera", str(tmp_path / "cli.yaml"), "--out", str(cli))
    assert code in (0, 3), out
    r = aerocal.calibrate(camera, observations=obs, points=points, groups=groups,
                          write_camera=str(tmp_path / "py.yaml"), out=str(tmp_path / "py.json"))
    assert r.valid == (code == 0)
    with open(cli) as f:
        expected = json.load(f)
    doc = json.loads(r.to_json())
    written = doc["calibration"].pop("camera_written", None), expected["calibration"].pop("camera_written", None)
    assert _without_clock(doc) == _without_clock(expected)
    assert (written[0] is None) == (written[1] is None)
    if written[0] is not None:  # the same camera file under another name
        assert (tmp_path / "py.yaml").read_text() == (tmp_path / "cli.yaml").read_text()
    assert r.sigma0 == expected["sigma0"]
    assert r.calibration["method"]["kind"] == "test field"
    on_disk = json.loads((tmp_path / "py.json").read_text())  # out=: the file to_json() gives
    on_disk["calibration"].pop("camera_written", None)
    assert _without_clock(on_disk) == _without_clock(doc)
    with pytest.raises(ValueError, match="--observations and --points go together"):
        aerocal.calibrate(camera, observations=obs)
    with pytest.raises(ValueError, match="sigma_px"):
        aerocal.calibrate(camera, observations=obs, points=points, sigma_px=-1)


def test_rig_stitch_equals_the_command(tmp_path):
    line = tmp_path / "uav4"
    code, out = run("simulate", "--rig", "uav4", "--exposures", "3", "--seed", "5", "--out", str(line))
    assert code == 0, out
    camera = str(line / "rig_truth.yaml")
    cli = tmp_path / "cli.json"
    code, out = run("rig", "stitch", "--camera", camera, "--project", str(line), "--dt-sigma-ms", "50",
                    "--out", str(cli))
    assert code == 0, out
    r = aerocal.rig_stitch(camera, str(line), dt_sigma_ms=50)
    with open(cli) as f:
        expected = json.load(f)
    assert _without_clock(json.loads(r.to_json())) == _without_clock(expected)
    assert r.valid and not r.failures and r.sigma0 == expected["sigma0"]
    assert len(r.rig_exposures) == len(expected["rig_exposures"])
    assert r.snooping["stopped"] is False
    with pytest.raises(ValueError, match="--mode must be line, per-exposure or angles"):
        aerocal.rig_stitch(camera, str(line), mode="spline")


def test_adjust_of_a_rig_block_equals_the_command(tmp_path):
    # The rig bundle of `aerocal adjust --project P` (P's camera file has a rig section), shared
    # code (tools/rig_adjust_run.h): the same document, clock keys aside, and typed accessors.
    flight = tmp_path / "dual"
    code, out = run("simulate", "--rig", "dual-lens", "--exposures", "8", "--out", str(flight))
    assert code == 0, out
    cli = tmp_path / "cli.json"
    code, out = run("adjust", "--project", str(flight), "--self-calibration", "c",
                    "--rig-lever-arms", "fixed", "--out", str(cli))
    assert code == 0, out
    block = aerocal.Block.read(str(flight))
    r = aerocal.adjust(block, self_calibration="c", rig_lever_arms="fixed")
    with open(cli) as f:
        expected = json.load(f)
    assert _without_clock(json.loads(r.to_json())) == _without_clock(expected)
    assert r.valid and r.sigma0 == expected["sigma0"]
    assert r.warnings == expected["warnings"]
    assert r.cameras[0].estimated["c"] == expected["cameras"][0]["estimated"]["c"]
    assert r.cameras[0].sigma["c"] == expected["cameras"][0]["sigma"]["c"]
    assert r.rig == expected["rig"]
    heads = r.heads
    assert [h["id"] for h in heads] == [h["id"] for h in expected["rig"]["heads"]]
    for h, e in zip(heads, expected["rig"]["heads"]):
        assert h["estimated"] == e["interior"] and h["sigma"] == e["interior_sigma"]
        assert h["mount_deg"] == e["mount_deg"] and h["lever_arm_m"] == e["lever_arm_m"]
    assert heads[1]["mount_deg"]["mode"] == "free" and heads[1]["mount_deg"]["sigma"][1] > 0
    assert heads[1]["lever_arm_m"]["mode"] == "fixed" and heads[1]["lever_arm_m"]["sigma"] == [None] * 3
    # The command's refusals, by the keyword's option name.
    with pytest.raises(ValueError, match="--self-calibration auto: not available for a rig project"):
        aerocal.adjust(block, self_calibration="auto")
    with pytest.raises(ValueError, match="--rig-mounts"):
        aerocal.adjust(block, rig_mounts="loose")
    # The rig bundle keeps no solved problem: its exposures' covariance is refused by name.
    image = expected["exposures"][0]["image"]
    with pytest.raises(ValueError, match="exposure " + image + "': a rig block"):
        r.covariance(["exposure " + image])


def test_rig_keywords_need_a_rig_block(flight):
    b = aerocal.Block.read(os.path.join(flight, "flight"))
    with pytest.raises(ValueError, match="rig camera file"):
        aerocal.adjust(b, rig_mounts="free")
    assert aerocal.adjust(b).heads == [] and aerocal.adjust(b).rig is None


def test_rig_stitched_image_equals_the_command(tmp_path):
    from PIL import Image  # Debian's python3-pil (a dependency of python3-matplotlib)
    photo = os.path.join(SHARED, "odm_boruszyn_kap_frames", "images", "img_4880.jpg")
    if not os.path.exists(photo):
        pytest.skip("../shared/data/odm_boruszyn_kap_frames is absent (the scene's texture)")
    sim = tmp_path / "uav4"
    code, out = run("simulate", "--rig", "uav4", "--exposures", "2", "--format-scale", "0.2", "--seed", "3",
                    "--render-images", "--texture", photo, "--texture-gsd-m", "0.25", "--grey-noise-dn", "1",
                    "--out", str(sim))
    assert code == 0, out
    camera, images = str(sim / "rig_truth.yaml"), str(sim / "images")
    stitched = tmp_path / "stitched"
    code, out = run("rig", "stitch", "--camera", camera, "--project", str(sim), "--standard-radius-px", "80",
                    "--images", images, "--stitched-out", str(stitched), "--out", str(tmp_path / "cli.json"))
    assert code == 0, out
    with open(tmp_path / "cli.json") as f:
        expected = json.load(f)["stitched_images"]
    r = aerocal.rig_stitch(camera, str(sim), standard_radius_px=80, images=images)
    assert len(expected) == 2
    for entry in expected:
        got = r.stitched_image(entry["image"])
        # The same pixels as the command's TIFFs, and the same figures.
        np.testing.assert_array_equal(got["pixels"], np.asarray(Image.open(entry["file"])))
        np.testing.assert_array_equal(got["mask"], np.asarray(Image.open(entry["mask"])))
        assert got["pixels"].shape == (entry["height_px"], entry["width_px"])
        assert int((got["mask"] == 255).sum()) == entry["valid_pixels"]
        for key in ("radiometry", "overlap_disagreement_dn", "warnings", "bits"):
            assert got[key] == entry[key], key
    with pytest.raises(ValueError, match="not an exposure of the rig stitch result"):
        r.stitched_image("nothing_like_this")
    with pytest.raises(ValueError, match="feather_px must be within 1..255"):
        r.stitched_image(expected[0]["image"], feather_px=0)


def test_pushbroom_calibrate_equals_the_command(tmp_path):
    sim = tmp_path / "pb"
    code, out = run("simulate", "--pushbroom", "--out", str(sim))
    assert code == 0, out
    files = [str(sim / f) for f in ("camera_nominal.yaml", "pos.csv", "observations.csv", "points.csv")]
    cli = tmp_path / "cli.json"
    code, out = run("pushbroom", "calibrate", "--camera", files[0], "--pos", files[1], "--observations",
                    files[2], "--points", files[3], "--degree", "3", "--out", str(cli))
    assert code in (0, 3), out
    r = aerocal.pushbroom_calibrate(*files, degree=3)
    assert r.valid == (code == 0)
    with open(cli) as f:
        expected = json.load(f)
    assert _without_clock(json.loads(r.to_json())) == _without_clock(expected)
    body = {k: v for k, v in expected.items() if k != "schema_version"}  # the file's envelope
    assert _without_clock(r.document) == _without_clock(body)
    assert r.printed.splitlines()[0] in out
    with pytest.raises(TypeError, match="unknown option 'degre'"):
        aerocal.pushbroom_calibrate(*files, degre=3)
    with pytest.raises(ValueError, match="--datum must be gauge, reference or none"):
        aerocal.pushbroom_calibrate(*files, datum="middle")


def test_pushbroom_control_equals_the_command(tmp_path):
    photo = os.path.join(SHARED, "odm_boruszyn_kap_frames", "images", "img_4880.jpg")
    if not os.path.exists(photo):
        pytest.skip("../shared/data/odm_boruszyn_kap_frames is absent (the scene's texture)")
    sim = tmp_path / "pb"
    code, out = run("simulate", "--pushbroom", "--render-images", "--texture", photo, "--detectors", "100",
                    "--lines", "300", "--out", str(sim))
    assert code == 0, out
    inputs = dict(camera=str(sim / "camera_nominal.yaml"), pos=str(sim / "pos.csv"),
                  line_image=str(sim / "line_image.png"), reference_camera=str(sim / "reference" / "camera.yaml"),
                  reference_images=str(sim / "reference"))
    exposures = str(sim / "reference" / "exposures.csv")
    cli = tmp_path / "control"
    code, out = run("pushbroom", "control", *[a for k, v in inputs.items() for a in ("--" + k.replace("_", "-"), v)],
                    "--reference-exposures", exposures, "--search-px", "12", "--out", str(cli))
    assert code == 0, out
    r = aerocal.pushbroom_control(**inputs, reference_exposures=exposures, search_px=12)
    with open(cli / "control.json") as f:
        assert r["document"] == json.load(f)
    # The arrays hold what observations.csv and points.csv hold, row for row.
    with open(cli / "points.csv") as f:
        rows = list(csv.DictReader(f))
    assert r["points"]["id"] == [row["point"] for row in rows]
    assert r["points"]["xyz_m"].shape == (len(rows), 3) and np.all(r["points"]["sigma_m"] > 0)
    np.testing.assert_allclose(r["points"]["xyz_m"][:, 2], [float(row["Z"]) for row in rows], rtol=1e-9)
    # One line-image observation per control point (the reference rays made the point).
    n = len(r["observations"]["point"])
    assert sorted(r["observations"]["point"]) == sorted(r["points"]["id"])
    assert r["observations"]["detector_line"].shape == (n, 2)
    with pytest.raises(TypeError, match="unknown option 'search'"):
        aerocal.pushbroom_control(**inputs, reference_exposures=exposures, search=3)
    with pytest.raises(ValueError, match="give one of --reference-exposures and --reference-result"):
        aerocal.pushbroom_control(**inputs)


def test_rig_design_equals_the_command(tmp_path):
    camera = os.path.join(SOURCE, "configs", "rig_uav4.yaml")
    out = tmp_path / "design.json"
    code, text = run("rig", "design", "--camera", camera, "--height-m", "300", "--out", str(out))
    assert code == 0, text
    with open(out) as f:
        expected = json.load(f)
    doc = aerocal.rig_design(camera, height_m=300)
    assert doc == expected
    assert doc["height_m"] == 300 and len(doc["heads"]) == 4 and doc["standard_positions"]
    with pytest.raises(ValueError, match="grid_cells"):
        aerocal.rig_design(camera, height_m=300, grid_cells=5)


def test_rig_error_analysis_equals_the_command(tmp_path):
    camera = os.path.join(SOURCE, "configs", "rig_dual_lens.yaml")
    limits = os.path.join(SOURCE, "configs", "rig_dual_lens_limits.yaml")
    out = tmp_path / "ea.json"
    code, text = run("rig", "error-analysis", "--camera", camera, "--limits", limits, "--samples", "2000",
                     "--no-plots", "--out", str(out))
    assert code == 0, text
    with open(out) as f:
        expected = json.load(f)
    # The command names its CSV beside --out; the function writes no file.
    assert expected["monte_carlo"].pop("histogram_csv") == "ea_histogram.csv"
    doc = aerocal.rig_error_analysis(camera, limits, samples=2000)
    assert doc == expected
    # Every Monte-Carlo sample lies within the maximum error of all sources at their limits (the
    # worst case), and for errors this small the linear propagation's bound is the Monte-Carlo's.
    assert doc["worst_case"][-1]["group"] == "all"
    assert 0 < doc["monte_carlo"]["max_radial_px"] <= doc["worst_case"][-1]["max_radial_px"]
    linear, mc = doc["linear"]["bound_radial_px"], doc["monte_carlo"]["bound_radial_px"]
    assert abs(linear - mc) < 0.15 * linear
    with pytest.raises(ValueError, match="--target"):
        aerocal.rig_error_analysis(camera, limits, target="nohead:1,1")
    with pytest.raises(ValueError, match="--samples must be within 0..10000000"):
        aerocal.rig_error_analysis(camera, limits, samples=10**9)


def _board_corners(camera, poses, distance_m, rng, noise_px):
    """A 9 x 6 chessboard (25 mm) seen from `poses` (omega, phi, kappa in degrees about the board's
    centre, the camera `distance_m` away on its axis): the inner corners row-major, as OpenCV's
    detector orders them, through the camera file's own camera, with Gaussian noise."""
    xyz = np.array([[c * 0.025, r * 0.025, 0.0] for r in range(6) for c in range(9)])
    corners = {}
    for i, (om, ph, ka) in enumerate(np.radians(poses)):
        rx = np.array([[1, 0, 0], [0, np.cos(om), -np.sin(om)], [0, np.sin(om), np.cos(om)]])
        ry = np.array([[np.cos(ph), 0, np.sin(ph)], [0, 1, 0], [-np.sin(ph), 0, np.cos(ph)]])
        rz = np.array([[np.cos(ka), -np.sin(ka), 0], [np.sin(ka), np.cos(ka), 0], [0, 0, 1]])
        p = ((rz @ rx @ ry) @ (xyz - xyz.mean(axis=0)).T).T - [0, 0, distance_m]  # camera frame
        pixels = camera.ray_to_image(p[:, :2] / -p[:, 2:3]) + rng.normal(0, noise_px, (len(xyz), 2))
        corners[f"board{i:02d}"] = np.array([[float(f"{v:.4f}") for v in row] for row in pixels])
    return corners


def test_calibrate_from_board_corners(tmp_path):
    model = "model: brown_fraser_10\npixel_size_mm: 0.006\nformat_px: [6000, 4000]\n"
    (tmp_path / "truth.yaml").write_text(model + "interior: {c: 50.3, x0: 0.04, y0: -0.03, K1: 2.0e-5}\n")
    nominal = str(tmp_path / "nominal.yaml")
    (tmp_path / "nominal.yaml").write_text(model + "interior: {c: 50.0}\n")
    poses = [(0, 0, 0), (25, 0, 0), (-25, 0, 0), (0, 25, 0), (0, -25, 0), (20, 20, 90), (-20, 20, 90),
             (20, -20, 180), (-15, -20, 270)]
    truth = aerocal.Camera.read(str(tmp_path / "truth.yaml"))
    corners = _board_corners(truth, poses, 0.5, np.random.default_rng(7), 0.05)
    r = aerocal.calibrate(nominal, corners=corners, board="chessboard:9x6:25", sigma_px=0.05)
    doc = json.loads(r.to_json())
    assert r.valid and r.calibration["data"]["observations"] == 9 * 54
    assert r.calibration["method"]["detector"] == "given (corners measured by the caller)"
    cam = doc["cameras"][0]
    for name in ("c", "x0", "y0", "K1"):  # the truth within 3 sigma
        assert abs(cam["estimated"][name] - truth.params[name]) < 3 * cam["sigma"][name], name
    # The same marks as a test field's files give the same adjustment to 1e-9 (the board's points on
    # Z = 0 with the board's sigma, control).
    with open(tmp_path / "obs.csv", "w") as f:
        f.write("image,point,col,row,sigma_px\n")
        for image, pixels in corners.items():
            for k, (col, row) in enumerate(pixels):
                f.write(f"{image},r{k // 9}c{k % 9},{col:.4f},{row:.4f},0.05\n")
    with open(tmp_path / "points.csv", "w") as f:
        f.write("point,X,Y,Z,sX,sY,sZ,role\n")
        for k in range(54):
            f.write(f"r{k // 9}c{k % 9},{k % 9 * 0.025!r},{k // 9 * 0.025!r},0,1e-05,1e-05,1e-05,control\n")
    code, out = run("calibrate", "--camera", nominal, "--observations", str(tmp_path / "obs.csv"), "--points",
                    str(tmp_path / "points.csv"), "--sigma-px", "0.05", "--out", str(tmp_path / "cli.json"))
    assert code == 0, out
    with open(tmp_path / "cli.json") as f:
        cli = json.load(f)
    assert cli["redundancy"] == doc["redundancy"]
    assert cli["sigma0"] == pytest.approx(doc["sigma0"], rel=1e-9)
    for key in ("estimated", "sigma"):
        for name, value in cli["cameras"][0][key].items():
            assert cam[key][name] == pytest.approx(value, rel=1e-9, abs=1e-18), (key, name)
    # Bad marks are ValueErrors naming the image.
    with pytest.raises(ValueError, match=r"corners\['board00'\]: 53 marks, the board has 54"):
        aerocal.calibrate(nominal, corners={**corners, "board00": corners["board00"][1:]},
                          board="chessboard:9x6:25")
    with pytest.raises(ValueError, match=r"corners\['board01'\]\[0\]: \(-7, 3\) is not a pixel"):
        bad = corners["board01"].copy()
        bad[0] = (-7, 3)
        aerocal.calibrate(nominal, corners={**corners, "board01": bad}, board="chessboard:9x6:25")
    with pytest.raises(ValueError, match="corners needs board"):
        aerocal.calibrate(nominal, corners=corners)
    with pytest.raises(ValueError, match="shape"):
        aerocal.calibrate(nominal, corners={"a": [1, 2, 3]}, board="chessboard:9x6:25")


def _directions_both_ways(tmp_path, camera, rows):
    """The directions file of `rows` calibrated by the command and by the module: the same result."""
    directions = tmp_path / "directions.csv"
    directions.write_text("\n".join(rows) + "\n")
    cli = tmp_path / "cli.json"
    code, out = run("calibrate", "--camera", str(camera), "--directions", str(directions), "--out", str(cli))
    assert code in (0, 3), out
    r = aerocal.calibrate(str(camera), directions=str(directions))
    with open(cli) as f:
        expected = json.load(f)
    assert _without_clock(json.loads(r.to_json())) == _without_clock(expected)
    return directions, cli, code, r, expected


def test_calibrate_from_directions_equals_the_command(tmp_path):
    camera = tmp_path / "camera.yaml"
    camera.write_text("name: lab\npixel_size_mm: 0.006\nformat_px: [6000, 4000]\ninterior: {c: 50.0}\n")
    # A 9 x 9 collimator array: t = (sin a cos e, sin e, -cos a cos e) (docs/formats.md), measured
    # through the camera file's own camera with 0.05 px noise.
    a, e = np.meshgrid(np.radians(np.linspace(-17, 17, 9)), np.radians(np.linspace(-11, 11, 9)))
    t = np.stack([np.sin(a) * np.cos(e), np.sin(e), -np.cos(a) * np.cos(e)], axis=-1).reshape(-1, 3)
    pixels = aerocal.Camera.read(str(camera)).ray_to_image(t[:, :2] / -t[:, 2:3])
    pixels += np.random.default_rng(5).normal(0.0, 0.05, pixels.shape)
    rows = ["target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec"]
    for k, (p, ak, ek) in enumerate(zip(pixels, np.degrees(a).ravel(), np.degrees(e).ravel())):
        rows.append(f"C{k},{p[0]:.5f},{p[1]:.5f},0.05,{ak:.6f},{ek:.6f},0.5")
    directions, cli, code, r, expected = _directions_both_ways(tmp_path, camera, rows)
    assert r.valid == (code == 0)
    assert r.calibration["method"] == expected["calibration"]["method"]
    with pytest.raises(ValueError, match="give either directions"):
        aerocal.calibrate(str(camera), directions=str(directions), observations=str(directions))
    # The certificate of that result, as `aerocal certificate` writes it into the same folder.
    cert = tmp_path / "cert"
    code_cli, text = run("certificate", "--result", str(cli), "--out", str(cert), "--no-render")
    assert code_cli in (0, 3), text
    with open(cert / "certificate.json") as f:
        expected_cert = json.load(f)
    code_py, document = aerocal.certificate(str(cli), str(cert), render=False)
    assert (code_py, document) == (code_cli, expected_cert)
    assert document["kind"] == "certificate" and sorted(os.listdir(cert)) == ["certificate.json"]
    with pytest.raises(ValueError, match="lab.yaml"):
        aerocal.certificate(str(cli), str(cert), lab=str(tmp_path / "lab.yaml"))


def test_calibrate_rig_heads_from_directions_equals_the_command(tmp_path):
    # Two heads of a rig (the second turned by -20 deg about y) before one collimator array; the
    # directions file's unit column names each row's head (docs/formats.md "Several units").
    head = "pixel_size_mm: 0.006, format_px: [6000, 4000], interior: {c: 50.0}"
    rig = tmp_path / "rig.yaml"
    rig.write_text("name: lab rig\nrig:\n  reference_head: A\n  heads:\n"
                   f"    - {{id: A, {head}}}\n    - {{id: B, {head}, mount_deg: [0, -20, 0]}}\n")
    camera = tmp_path / "camera.yaml"
    camera.write_text("name: lab\npixel_size_mm: 0.006\nformat_px: [6000, 4000]\ninterior: {c: 50.0}\n")
    a, e = np.meshgrid(np.radians(np.arange(-15, 36, 3.0)), np.radians(np.linspace(-9, 9, 7)))
    t = np.stack([np.sin(a) * np.cos(e), np.sin(e), -np.cos(a) * np.cos(e)], axis=-1).reshape(-1, 3)
    rng = np.random.default_rng(6)
    rows = ["target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,unit"]
    for unit, phi in (("A", 0.0), ("B", np.radians(-20.0))):
        ry = np.array([[np.cos(phi), 0, np.sin(phi)], [0, 1, 0], [-np.sin(phi), 0, np.cos(phi)]])
        v = t @ ry  # head-frame rays, M^T t per row
        pixels = aerocal.Camera.read(str(camera)).ray_to_image(v[:, :2] / -v[:, 2:3])
        pixels += rng.normal(0.0, 0.05, pixels.shape)
        for k, (p, ak, ek) in enumerate(zip(pixels, np.degrees(a).ravel(), np.degrees(e).ravel())):
            if 0 <= p[0] <= 5999 and 0 <= p[1] <= 3999:
                rows.append(f"C{k},{p[0]:.5f},{p[1]:.5f},0.05,{ak:.6f},{ek:.6f},0.5,{unit}")
    _, _, _, r, _ = _directions_both_ways(tmp_path, rig, rows)
    assert [u["id"] for u in r.calibration["units"]] == ["A", "B"]
    assert abs(r.calibration["units"][1]["mount_opk_deg"][1] + 20.0) < 0.01

MATCH_CAMERA = """name: small
pixel_size_mm: 0.009
format_px: [600, 400]
interior: {c: 50}
subimages:
  - {id: I, format_px: [340, 240], model: affine, params: [1, 0, 0, 0, 1, 0]}
  - {id: II, format_px: [340, 240], model: affine, params: [1, 0, 260, 0, 1, 0]}
  - {id: III, format_px: [340, 240], model: affine, params: [1, 0, 0, 0, 1, 160]}
  - {id: IV, format_px: [340, 240], model: affine, params: [1, 0, 260, 0, 1, 160]}
"""


def lowpassed_noise(seed, rows, cols):
    """White noise low-passed by a Gaussian of 2 px, stretched to 8 bit: a texture to match."""
    noise = np.random.default_rng(seed).normal(size=(rows, cols))
    fy, fx = np.fft.fftfreq(rows)[:, None], np.fft.fftfreq(cols)[None, :]
    scene = np.real(np.fft.ifft2(np.fft.fft2(noise) * np.exp(-2 * np.pi ** 2 * 4.0 * (fx ** 2 + fy ** 2))))
    return (255 * (scene - scene.min()) / (scene.max() - scene.min())).astype(np.uint8)


def test_match_equals_the_command(tmp_path):
    from PIL import Image
    camera = tmp_path / "camera.yaml"
    camera.write_text(MATCH_CAMERA)
    # One scene of the 600 x 400 virtual format (white noise low-passed by a Gaussian of 2 px),
    # cut along the nominal mappings into four 340 x 240 sub-images with 80 px overlaps.
    scene = lowpassed_noise(7, 400, 600)
    images = {}
    for sid, (e, f) in {"I": (0, 0), "II": (260, 0), "III": (0, 160), "IV": (260, 160)}.items():
        path = tmp_path / f"{sid}.png"
        Image.fromarray(scene[f:f + 240, e:e + 340]).save(path)
        images[sid] = str(path)
    text = ",".join(f"{k}={v}" for k, v in images.items())
    cli = tmp_path / "cli.csv"
    code, out = run("match", "--camera", str(camera), "--frame", "1", "--images", text, "--out", str(cli))
    assert code == 0, out
    py_csv = tmp_path / "py.csv"
    r = aerocal.match(str(camera), images, frame="1", out=str(py_csv))
    assert py_csv.read_text() == cli.read_text()  # the command's file, byte for byte
    n = len(r["point"])
    assert n > 0 and r["pixel"].shape == (n, 2) and r["sigma_px"].shape == (n,)
    assert set(r["subimage"]) <= set(images) and set(r["frame"]) == {"1"}
    assert r["table"].splitlines()[0].split()[:2] == ["frame", "strip"]
    with pytest.raises(ValueError, match="--images needs --frame"):
        aerocal.match(str(camera), images)
    with pytest.raises(ValueError, match="--detector applies to --search descriptors"):
        aerocal.match(str(camera), images, frame="1", detector="sift")


def test_both_searches_find_sub_images_misplaced_against_the_nominal_mappings(tmp_path):
    """Sub-image IV is cut 3 px right and 2 px down of where the camera file puts it: the
    predicted search (correlation around the nominal prediction) and the descriptor search must
    both find the true offsets, so every tie meets through the TRUE mappings."""
    from PIL import Image
    camera = tmp_path / "camera.yaml"
    camera.write_text(MATCH_CAMERA)
    scene = lowpassed_noise(11, 400, 610)
    true_offsets = {"I": (0, 0), "II": (260, 0), "III": (0, 160), "IV": (263, 158)}
    images = {}
    for sid, (e, f) in true_offsets.items():
        path = tmp_path / f"{sid}.png"
        Image.fromarray(scene[f:f + 240, e:e + 340]).save(path)
        images[sid] = str(path)
    for search, detector in (("predicted", None), ("descriptors", "sift")):
        r = aerocal.match(str(camera), images, frame="1", search=search, detector=detector)
        rows = {}
        for point, sub, uv in zip(r["point"], r["subimage"], r["pixel"]):
            rows.setdefault(point, []).append(uv + np.array(true_offsets[sub]))
        gaps = np.array([v[0] - v[1] for v in rows.values() if len(v) == 2])
        strips = {p.rsplit("_", 1)[0] for p in rows}
        assert strips == {"I-II", "I-III", "I-IV", "II-III", "II-IV", "III-IV"}, (search, strips)
        assert len(gaps) >= 12, (search, len(gaps))
        assert np.sqrt(np.mean(gaps ** 2)) < 0.05, (search, np.sqrt(np.mean(gaps ** 2)))
