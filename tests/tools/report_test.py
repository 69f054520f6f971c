"""Tests of the flight report renderer tools/report/aerocal_report.py (python unittest).

Run by ctest as tools/report (tests/tools/report.cmake), or by hand from tests/tools:
  python3 -m unittest -v report_test
The fixture tests/data/report/result.json is a flight result: real `aerocal stitch` output for eight
simulated exposures and three adjustments in the FORMATS.md keys (see tests/data/report/README.md).
"""
import base64
import html.parser
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.environ.get("AEROCAL_REPORT_SCRIPT",
                        os.path.join(HERE, "..", "..", "tools", "report", "aerocal_report.py"))
FIXTURE = os.environ.get("AEROCAL_REPORT_FIXTURE", os.path.join(HERE, "..", "data", "report", "result.json"))
CHROMIUM = "/usr/bin/chromium"
PNG_URI = '<img src="data:image/png;base64,'
# Figures of the fixture: sigma0 per exposure, residual vectors, distortion of camera cam1, check map.
FIXTURE_FIGURES = 4


def run_report(result_path, html_path):
    return subprocess.run([sys.executable, SCRIPT, result_path, html_path], capture_output=True, text=True,
                          timeout=120)


class Tables(html.parser.HTMLParser):
    """Collects every element id, and the text of the cells of every table by table id."""

    def __init__(self):
        super().__init__()
        self.ids, self.tables, self.headings = set(), {}, []
        self._table, self._row, self._cell, self._heading = None, None, None, None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        if tag == "table":
            self._table = self.tables.setdefault(attrs.get("id", ""), [])
        elif tag == "tr" and self._table is not None:
            self._row = []
            self._table.append(self._row)
        elif tag in ("td", "th") and self._row is not None:
            self._cell = []
        elif tag in ("h1", "h2", "h3"):
            self._heading = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._row.append(" ".join("".join(self._cell).split()))
            self._cell = None
        elif tag == "table":
            self._table, self._row = None, None
        elif tag in ("h1", "h2", "h3") and self._heading is not None:
            self.headings.append("".join(self._heading).strip())
            self._heading = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)
        if self._heading is not None:
            self._heading.append(data)

    def row(self, table_id, label):
        """The cells of the first row of table_id whose first cell is label."""
        for r in self.tables[table_id]:
            if r and r[0] == label:
                return r
        raise AssertionError(f"no row {label!r} in table {table_id!r}")


class FixtureReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="aerocal_report_")
        cls.html_path = os.path.join(cls.dir, "report.html")
        cls.proc = run_report(FIXTURE, cls.html_path)
        with open(FIXTURE) as f:
            cls.doc = json.load(f)
        cls.html = ""
        if os.path.exists(cls.html_path):
            with open(cls.html_path, encoding="utf-8") as f:
                cls.html = f.read()
        cls.page = Tables()
        cls.page.feed(cls.html)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def adjustment(self, name):
        return next(a for a in self.doc["adjustments"] if a["name"] == name)

    def test_renders_and_leaves_only_the_report(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stderr)
        self.assertEqual(self.proc.stderr, "")
        self.assertEqual(os.listdir(self.dir), ["report.html"])
        self.assertTrue(self.html.startswith("<!DOCTYPE html>"))

    def test_has_the_sections_and_tables(self):
        for heading in ("1. Summary", "2. Project", "3. Stitching of the sub-images", "3.1 Model comparison",
                        "3.2 Flight stability", "3.3 sigma0 per exposure", "4. Adjustments",
                        "4.1 Conventional triangulation", "4.2 Self-calibrating triangulation",
                        "5. Left out: images, points and observations the adjustments did not use",
                        "6. Comparison of the adjustments", "7. Calibration", "7.1 Distortion curves",
                        "8. Image residuals over the format", "9. Check-point errors"):
            self.assertIn(heading, self.page.headings)
        for element in ("summary-steps", "stitch-model-comparison", "stitch-model-choice", "stitch-stability",
                        "stitch-sigma0-plot", "adj-conventional-points", "adj-self-calibration-points",
                        "adj-joint-points", "adj-joint-subimages", "adj-joint-stitching-sigma0", "comparison-table",
                        "calib-self-calibration-cam1", "calib-joint-cam1", "distortion-cam1", "residual-plot",
                        "check-map"):
            self.assertIn(element, self.page.ids)
        self.assertNotIn("calib-conventional-cam1", self.page.ids)  # interior held fixed there
        self.assertNotIn("not available", self.html)

    def test_stitching_tables_show_the_fixture_figures(self):
        stitching = self.doc["stitching"]
        models = {m["model"]: m for m in stitching["stability"]["models"]}
        for model, m in models.items():
            row = self.page.row("stitch-stability", model)
            self.assertEqual(row[4], f"{m['mean_sigma0_px']:.4f}")
            self.assertEqual(row[5], f"{m['std_sigma0_px']:.4f}")
        # Frame 0001 is flagged by the translation model's stability test in the fixture.
        self.assertIn("0001:", self.page.row("stitch-stability", "translation")[6])
        chosen = [f["model_choice"]["chosen"] for f in stitching["frames"]]
        for model in models:
            row = self.page.row("stitch-model-comparison", model)
            self.assertEqual(int(row[2]), chosen.count(model))
        for f in stitching["frames"]:
            row = self.page.row("stitch-model-choice", f["frame"])
            self.assertIn(f["model_choice"]["chosen"], row)

    def test_adjustment_tables_show_the_fixture_figures(self):
        for name in ("conventional", "self_calibration", "joint"):
            a = self.adjustment(name)
            table_id = "adj-" + name.replace("_", "-") + "-points"
            check = self.page.row(table_id, "check")
            self.assertEqual(int(check[1]), a["check"]["n"])
            self.assertEqual(check[2:5], [f"{v:.4f}" for v in a["check"]["rmse_m"]])
            self.assertEqual(check[5], f"{a['check']['planimetric_rmse_m']:.4f}")
            self.assertEqual(check[6], f"{a['check']['spatial_rmse_m']:.4f}")
            self.assertEqual(int(self.page.row(table_id, "control")[1]), a["control"]["n"])
        names = ["conventional", "self_calibration", "joint"]
        self.assertEqual(self.page.row("comparison-table", "check RMSE spatial [m]")[1:],
                         [f"{self.adjustment(n)['check']['spatial_rmse_m']:.4f}" for n in names])
        self.assertEqual(self.page.row("comparison-table", "sigma0 [um]")[1:],
                         [f"{self.adjustment(n)['sigma0_um']:.3f}" for n in names])

    def test_calibration_table_is_initial_correction_estimate_sigma(self):
        cam = self.adjustment("self_calibration")["cameras"][0]
        c = self.page.row("calib-self-calibration-cam1", "c")
        self.assertEqual(c[1], "mm")
        self.assertEqual(c[2:5], [f"{cam['initial']['c']:.5f}", f"{cam['estimated']['c'] - cam['initial']['c']:.5f}",
                                  f"{cam['estimated']['c']:.5f}"])
        self.assertEqual(c[5], f"{cam['sigma']['c']:.2e}")
        k1 = self.page.row("calib-self-calibration-cam1", "K1")
        self.assertEqual(k1[1], "mm^-2")
        self.assertEqual(k1[4], f"{cam['estimated']['K1']:.4e}")
        self.assertEqual(self.page.row("calib-self-calibration-cam1", "B1")[5], "fixed")
        units = [self.page.row("calib-joint-cam1", p)[1] for p in ("c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2")]
        self.assertEqual(units, ["mm", "mm", "mm", "mm^-2", "mm^-4", "mm^-6", "mm^-1", "mm^-1", "1", "1"])

    def test_figures_are_embedded_pngs_and_nothing_is_fetched(self):
        self.assertEqual(self.html.count(PNG_URI), FIXTURE_FIGURES)
        for chunk in self.html.split(PNG_URI)[1:]:
            png = base64.b64decode(chunk[:chunk.index('"')])
            self.assertTrue(png.startswith(b"\x89PNG\r\n\x1a\n"))
            self.assertGreater(len(png), 10000)
        self.assertNotIn("<script", self.html)
        self.assertNotIn("<link", self.html)
        self.assertNotIn("http://", self.html)
        self.assertNotIn("https://", self.html)

    def test_figure_captions_state_the_scales(self):
        self.assertIn("mean residual per cell of a 10 x 9 grid, exaggerated", self.html)
        self.assertIn("Z error as colour", self.html)
        self.assertIn("half-diagonal 83.0 mm", self.html)

    @unittest.skipUnless(os.path.exists(CHROMIUM), f"{CHROMIUM} is not installed: headless rendering not checked")
    def test_renders_in_a_headless_browser(self):
        try:
            from PIL import Image  # python3-pil, a dependency of Debian's python3-matplotlib
        except ImportError:
            self.skipTest("python3-pil is not installed: the screenshot cannot be inspected")
        profile = tempfile.mkdtemp(prefix="aerocal_chromium_")
        shot = os.path.join(self.dir, "screenshot.png")
        try:
            proc = subprocess.run(
                [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 f"--user-data-dir={profile}", f"--screenshot={shot}", "--window-size=1200,3000",
                 "file://" + self.html_path],
                capture_output=True, text=True, timeout=120, env=dict(os.environ, HOME=profile))
            self.assertTrue(os.path.exists(shot), proc.stderr[-2000:])
            with Image.open(shot) as image:
                self.assertEqual(image.size, (1200, 3000))
                gray = image.convert("L")
                histogram = gray.histogram()
                ink = sum(histogram[:200]) / (1200 * 3000)
                # A rendered page has text, table rules and the plot: a few percent of dark pixels,
                # many grey levels; a blank or error page has almost none.
                self.assertGreater(ink, 0.02)
                self.assertGreater(sum(1 for n in histogram if n > 0), 100)
                title = gray.crop((0, 0, 600, 60)).histogram()
                self.assertGreater(sum(title[:100]), 500)  # the title's glyphs
        finally:
            shutil.rmtree(profile, ignore_errors=True)
            if os.path.exists(shot):
                os.remove(shot)


class BadInput(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="aerocal_report_bad_")
        self.out = os.path.join(self.dir, "report.html")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def check_refused(self, content, message):
        path = os.path.join(self.dir, "result.json")
        with open(path, "w") as f:
            f.write(content)
        proc = run_report(path, self.out)
        self.assertEqual(proc.returncode, 2)
        self.assertEqual(proc.stderr.count("\n"), 1, proc.stderr)
        self.assertTrue(proc.stderr.startswith("error: "), proc.stderr)
        self.assertIn(message, proc.stderr)
        self.assertEqual(sorted(os.listdir(self.dir)), ["result.json"])

    def test_not_json(self):
        self.check_refused('{"kind": "flight", "stitching": ', "not a JSON document")

    def test_not_a_flight_result(self):
        self.check_refused('{"kind": "stitch", "sigma0": 1.0}', 'kind is "stitch", expected "flight"')
        self.check_refused("[1, 2, 3]", "top level is not an object")

    def test_wrong_schema_version(self):
        self.check_refused('{"kind": "flight", "schema_version": 1}',
                           'schema_version is 1, expected 2 (kind "flight")')
        self.check_refused('{"kind": "flight"}', 'schema_version is null, expected 2 (kind "flight")')

    def test_missing_file(self):
        proc = run_report(os.path.join(self.dir, "absent.json"), self.out)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("cannot read", proc.stderr)
        self.assertFalse(os.path.exists(self.out))

    def test_usage(self):
        proc = subprocess.run([sys.executable, SCRIPT], capture_output=True, text=True, timeout=60)
        self.assertEqual(proc.returncode, 2)
        self.assertTrue(proc.stderr.startswith("error: usage"))


class TolerantInput(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="aerocal_report_tolerant_")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def render(self, doc):
        path, out = os.path.join(self.dir, "result.json"), os.path.join(self.dir, "report.html")
        with open(path, "w") as f:
            json.dump(doc, f)
        proc = run_report(path, out)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        page = Tables()
        with open(out, encoding="utf-8") as f:
            text = f.read()
        page.feed(text)
        return text, page

    def test_missing_sections_say_not_available(self):
        text, page = self.render({"kind": "flight", "schema_version": 2})
        self.assertIn("Stitching: not available", text)
        self.assertIn("Adjustments: not available", text)
        self.assertIn("Check-point errors: not available", text)
        self.assertEqual(text.count(PNG_URI), 0)

    def test_draft_key_names_are_not_read(self):
        # The brief's draft spellings (model_choice.models, stability.per_model with string flags,
        # check points with X/dX and rmse_planimetric_m / rmse_spatial_m) are no keys of the
        # schemas (docs/schema): the report reads only the writers' keys (schema_keys_test.py) and
        # renders the rest.
        points = [{"point": f"K{k}", "X": 100.0 * k, "Y": 50.0 * (k % 3), "Z": 10.0, "dX": 0.01 * k, "dY": -0.02,
                   "dZ": 0.03 * (k % 2)} for k in range(1, 7)]
        doc = {"kind": "flight", "schema_version": 2, "camera_format": {"width_px": 1000, "height_px": 800, "pixel_size_mm": 0.01},
               "stitching": {"kind": "stitch", "model": "affine", "sigma0_px": 0.1,
                             "frames": [{"frame": "0001", "sigma0_px": 0.101, "converged": True,
                                         "model_choice": {"chosen": "affine", "reason": "because",
                                                          "models": [{"model": "conformal", "sigma0_px": 0.2,
                                                                      "redundancy": 40},
                                                                     {"model": "affine", "sigma0_px": 0.101,
                                                                      "redundancy": 38, "F": 30.0,
                                                                      "F_critical": 3.2, "against": "conformal",
                                                                      "significant": True}]}}],
                             "stability": {"mean_sigma0_px": 0.101, "std_sigma0_px": 0.0,
                                           "per_model": [{"model": "affine", "mean_sigma0_px": 0.1234,
                                                          "std_sigma0_px": 0.0056, "flagged_frames": ["0001"]}]}},
               "adjustments": [{"name": "conventional", "sigma0": 1.1, "sigma0_px": 0.22, "sigma0_um": 2.2,
                                "converged": False,
                                "check": {"n": 6, "rmse_m": [0.1, 0.2, 0.3], "rmse_planimetric_m": 0.2236,
                                          "rmse_spatial_m": 0.3742, "points": points},
                                "residuals": [{"image": "1", "point": "T", "col": 100 * k, "row": 80 * k,
                                               "v_col_px": 0.1, "v_row_px": -0.2} for k in range(1, 9)]}]}
        text, page = self.render(doc)
        self.assertNotIn("0.1234", text)
        self.assertNotIn("F = 30 > 3.2", text)
        self.assertNotIn("0.2236", text)
        self.assertIn("did not converge", text)
        self.assertIn("residual-plot", page.ids)
        # sigma0, residuals; no check map (its points are in the draft spelling), no interior curves
        self.assertEqual(text.count(PNG_URI), 2)

    def test_calibration_table_follows_the_results_camera_model(self):
        # A camera in another registered model: its table's names and units (the result's
        # camera_model), and no 10-parameter distortion curves drawn from absent K1..P2.
        table = [{"name": n, "unit": u, "group": "g"} for n, u in (("fx", "px"), ("fy", "px"), ("k1", "1"))]
        camera = {"id": "cam1", "model": "opencv", "initial": {"fx": 4000.0, "fy": 4000.0, "k1": 0.0},
                  "estimated": {"fx": 4012.5, "fy": 4011.0, "k1": -0.05}, "sigma": {"fx": 0.5, "fy": 0.5, "k1": 0.001}}
        doc = {"kind": "flight", "schema_version": 2,
               "camera_format": {"width_px": 1000, "height_px": 800, "pixel_size_mm": 0.01},
               "camera_model": {"name": "opencv", "id": 2, "parameters": table},
               "adjustments": [{"name": "self_calibration", "sigma0": 1.0, "converged": True,
                                "self_calibration": ["fx", "fy", "k1"], "cameras": [camera]}]}
        text, page = self.render(doc)
        row = page.row("calib-self-calibration-cam1", "fx")
        self.assertEqual(row[1], "px")
        self.assertEqual(row[4], "4012.50000")
        self.assertEqual(page.row("calib-self-calibration-cam1", "k1")[1], "1")
        self.assertNotIn("distortion-cam1", page.ids)
        self.assertIn("the camera is in the model opencv", text)

    def test_invalid_steps_and_suspected_model_errors_are_shown_in_red(self):
        doc = {"kind": "flight", "schema_version": 2, "valid": False,
               "failures": [{"step": "self-calibration", "reason": "sigma0 3.4 is above the limit 3"}],
               "adjustments": [{"name": "self_calibration", "sigma0": 3.4, "sigma0_px": 0.68, "converged": True,
                                "valid": False, "invalid_reasons": ["sigma0 3.4 is above the limit 3"],
                                "snooping": {"model_error_suspected": True,
                                             "model_error_evidence": ["3 independent of the 5 largest w on point C5"],
                                             "suggestion": "self-calibration may absorb it",
                                             "findings": ["point T442: one of these 2 observations holds a gross "
                                                          "error; they cannot be told apart"]}}]}
        text, page = self.render(doc)
        self.assertIn('<span class="bad">self-calibration: sigma0 3.4 is above the limit 3</span>', text)
        self.assertIn("model error suspected (3 independent of the 5 largest w on point C5)", text)
        self.assertIn("cannot be told apart", text)
        self.assertIn("no calibrated camera was written", text)
        self.assertEqual(page.row("summary-steps", "Self-calibrating triangulation")[2], "no")

    def test_warnings_and_the_joint_mapping_model_are_shown(self):
        # A joint adjustment whose translation mappings do not fit: its warnings by name on the
        # summary (step flagged) and in its section, with the mapping model and why.
        warning = {"name": "group_rms", "subject": "stitch_tie", "value": 14.1, "limit": 3,
                   "message": "residual group stitch_tie: RMS 14.1 sigma over 3678 observations (limit 3)"}
        doc = {"kind": "flight", "schema_version": 2,
               "adjustments": [{"name": "self_calibration", "sigma0": 1.0, "converged": True, "warnings": []},
                               {"name": "joint", "sigma0": 4.7, "converged": True, "mapping_model": "translation",
                                "mapping_model_reason": "given by the user", "mapping_scope": "per-flight",
                                "datum": "base sub-images III IV", "warnings": [warning]}]}
        text, page = self.render(doc)
        joint = page.tables["summary-steps"][-1]  # the last step that ran
        self.assertIn("mappings translation", joint[-1])
        self.assertIn("1 warning(s)", joint[-1])
        # A warning does not invalidate, and the verdict line says the warning (never a plain "valid").
        self.assertIn("Verdict: converged, with 1 warning(s)", text)
        self.assertNotIn("Verdict: valid", text)
        self.assertEqual(text.count("residual group stitch_tie: RMS 14.1 sigma"), 3)  # verdict, summary, section
        self.assertIn("Mapping model: translation (given by the user).", text)

    def test_what_snooping_cannot_judge_is_listed(self):
        # Check points resting on rays with r = 0 apart from the controlled check RMSE (the check
        # RMSE of every point kept), and each observation no test can judge with r, MDB and why.
        doc = {"kind": "flight", "schema_version": 2,
               "adjustments": [{"name": "self_calibration", "sigma0": 1.0, "converged": True,
                                "check": {"n": 2, "rmse_m": [0.3, 0.4, 1.2], "spatial_rmse_m": 1.3,
                                          "planimetric_rmse_m": 0.5},
                                "check_controlled": {"n": 1, "rmse_m": [0.1, 0.1, 0.2], "spatial_rmse_m": 0.2449,
                                                     "planimetric_rmse_m": 0.1414,
                                                     "uncontrolled_points": [{"point": "K10", "rays": 2,
                                                                              "difference_m": [0.0, 3.0, 4.0],
                                                                              "reason": "ray 0011: r = 0 on photo x"}]},
                                "snooping": {"uncontrolled": [{"image": "0011", "point": "K10", "rays": 2,
                                                               "r": [0.0, 0.48], "mdb_px": [None, 2.1],
                                                               "untestable": True,
                                                               "reason": "r = 0 on photo x: the component along "
                                                                         "the base of a two-ray point"}]}}]}
        text, page = self.render(doc)
        self.assertEqual(page.row("adj-self-calibration-points", "check")[6], "1.3000")
        self.assertEqual(page.row("adj-self-calibration-points", "check, controlled rays only")[1:2], ["1"])
        self.assertEqual(page.row("adj-self-calibration-uncontrolled-checks", "K10")[2], "5.0000")
        row = page.row("adj-self-calibration-uncontrolled", "0011")
        self.assertEqual(row[3:5], ["0.00, 0.48", "n/a, 2.1"])
        self.assertIn("two-ray point", row[5])
        self.assertIn("1 with r = 0", text)


def adjust_result(**extra):
    """A small `aerocal adjust --compare` result: one blunder rejected (1200 px, w 768), one image
    left out, a control survey left out, two weakly controlled observations."""
    residuals = [{"image": "A", "point": "P1", "col": 100.0, "row": 200.0, "v_col_px": 0.5, "v_row_px": -0.5,
                  "used": True, "r": [0.4, 0.5], "w_xy": [0.7, 0.8]},
                 {"image": "B", "point": "P1", "col": 300.0, "row": 100.0, "v_col_px": -0.3, "v_row_px": 0.4,
                  "used": True, "r": [0.3, 0.4], "w_xy": [0.5, 0.6]},
                 {"image": "B", "point": "P2", "col": 900.0, "row": 500.0, "v_col_px": 1000.0,
                  "v_row_px": -663.3, "used": False}]
    own = {"name": "ignored", "sigma0": 1.1, "sigma0_px": 1.1, "converged": True, "valid": True,
           "self_calibration": ["c"], "residuals": residuals,
           "rejected": [{"image": "B", "point": "P2", "by": "robust start", "residual_px": 1200.0, "w": 768.4,
                         "measured_px": [900.0, 500.0]}],
           "exposures": [{"image": "A", "X": 0.0, "Y": 0.0, "Z": 100.0, "omega": 0.1, "phi": 0.2, "kappa": 90.0,
                          "sigma": {"X": 0.01, "Y": 0.01, "Z": 0.02, "omega": 0.001, "phi": 0.001, "kappa": 0.001},
                          "used": True},
                         {"image": "C", "X": 5.0, "Y": 0.0, "Z": 100.0, "omega": 0.0, "phi": 0.0, "kappa": 90.0,
                          "sigma": {k: None for k in ("X", "Y", "Z", "omega", "phi", "kappa")}, "used": False}],
           "notes": ["image C sees 2 point(s) only: its orientation cannot be determined; left out"],
           "control": {"n": 1, "rmse_m": [0.01, 0.01, 0.01], "points": [
               {"point": "P1", "rays": 2, "surveyed": [0, 0, 0], "adjusted": [0.01, 0, 0],
                "difference_m": [0.01, 0.0, 0.0]}]},
           "control_left_out": [{"point": "P9", "rays": 3, "difference_m": [0.5, 0.0, 0.0], "w": 6.2,
                                 "components": {"plan": 6.2}}],
           "check": {"n": 1, "rmse_m": [0.02, 0.02, 0.02], "points": [
               {"point": "K1", "rays": 2, "surveyed": [1, 1, 0], "adjusted": [1.02, 1, 0],
                "difference_m": [0.02, 0.0, 0.0], "uncontrolled": "ray B: r = 0 on photo y"}]},
           "snooping": {"min_redundancy": 0.1, "uncontrolled": [
               {"image": "A", "point": "K1", "rays": 2, "r": [0.2, 0.0], "untestable": True, "reason": "r = 0"},
               {"image": "B", "point": "K1", "rays": 2, "r": [0.3, 0.05], "reason": "weak"}]},
           "warnings": []}
    doc = dict(own, kind="adjust", schema_version=3, project="p",
               camera_format={"width_px": 1000, "height_px": 800, "pixel_size_mm": 0.01},
               conventional=dict(own, self_calibration=[], name="x"))
    doc.update(extra)
    return doc


class WhatPeopleRead(unittest.TestCase):
    """Issue 33 item 1: per-point tables, rejected apart, left-out named, one consistent verdict."""
    setUp, tearDown, render = TolerantInput.setUp, TolerantInput.tearDown, TolerantInput.render

    def test_adjust_result_is_reported_with_its_conventional_reference(self):
        text, page = self.render(adjust_result())
        self.assertIn("aerocal block adjustment report", text)
        self.assertIn("4.1 Conventional triangulation", page.headings)
        self.assertIn("4.2 Self-calibrating triangulation", page.headings)

    def test_residuals_plotted_are_the_used_ones_and_the_blunder_is_listed_with_w(self):
        sys.path.insert(0, os.path.dirname(SCRIPT))
        import report_data
        doc = report_data.as_flight_document(adjust_result())
        self.assertEqual(len(report_data.residuals(doc["adjustments"][1])), 2)  # the 1200 px one is out
        text, page = self.render(adjust_result())
        row = page.row("adj-self-calibration-rejected", "B")
        self.assertEqual(row[3:6], ["1200.00", "768.4", "robust start"])
        self.assertIn("the 2 rejected are listed apart", text)  # one per adjustment panel

    def test_points_exposures_and_left_out_are_named_with_the_reason(self):
        text, page = self.render(adjust_result())
        check = page.row("adj-self-calibration-check-points", "K1")
        self.assertEqual(check[8:10], ["used, untestable rays", "ray B: r = 0 on photo y"])
        control = page.row("adj-self-calibration-control-points", "P9")
        self.assertEqual(control[7:9], ["6.2", "rejected"])
        exposure = page.row("adj-self-calibration-exposures", "C")
        self.assertEqual(exposure[-1], "no: left out")
        left = {(r[1], r[2]): r for r in page.tables["left-out-table"][1:]}
        self.assertIn("Conventional triangulation, Self-calibrating triangulation", left[("image", "C")][0])
        self.assertIn("w = 768.4", left[("observation", "image B point P2")][3])
        self.assertIn("w = 6.2", left[("control survey", "P9")][3])

    def test_weakly_controlled_rows_are_summarised_and_folded(self):
        text, _ = self.render(adjust_result())
        self.assertIn("2 observation(s) weakly controlled", text)
        self.assertIn("worst: image A point K1 (r = 0.000)", text)
        self.assertIn("<details><summary>Full list (2)</summary>", text)

    def test_the_verdict_follows_the_worst_finding(self):
        text, _ = self.render(adjust_result())
        self.assertIn('class="verdict ok"', text)
        suspect = adjust_result(snooping={"model_error_suspected": True, "model_error_evidence": ["sigma0 2 > 1.5"],
                                          "suggestion": "check the camera model"})
        text, _ = self.render(suspect)
        self.assertIn('class="verdict warn"', text)
        self.assertNotIn('class="verdict ok"', text)
        invalid = adjust_result(valid=False, invalid_reasons=["c not determinable"])
        text, _ = self.render(invalid)
        self.assertIn("Verdict: NOT VALID: Self-calibrating triangulation: c not determinable", text)

    def test_advice_depends_on_the_case(self):
        sys.path.insert(0, os.path.dirname(SCRIPT))
        import report_data
        import report_facts
        held = {"held": [{"parameter": "c", "reason": "not determinable (traded against the orientation)"}]}
        doc = report_data.as_flight_document(adjust_result(self_calibration_choice=held))
        advice = " ".join(report_facts.advice(doc))
        self.assertIn("Re-measure or remove the 1 rejected", advice)
        self.assertIn("Images left out (C)", advice)
        self.assertIn("Points seen in two images only (K1)", advice)
        # Two exposures are no aerial block: close-range advice, nothing about strips or GNSS.
        self.assertNotIn("GNSS", advice)
        self.assertNotIn("strips", advice)
        self.assertIn("convergent and rolled", advice)

    def test_the_dynamic_resolution_section_restates_the_quality_numbers(self):
        # `flight --quality`: C++ copies the quality results and computes the resampling loss
        # (tools/dynamic_resolution.h); the report shows them per image and axis, unchanged.
        axis = {"axis": "x", "direction": "along_track", "count": 4, "type_a_u_cy_px": 0.0004,
                "type_b_u_cy_px": 0.0009, "mtf50_u_cy_px": 0.001}
        section = {
            "sources": ["q/raw_I.json", "q/virtual.json", "q/bars.json"], "method": "ISO 12233:2017 e-SFR",
            "edges": [{"source": "q/raw_I.json", "image_kind": "raw", "sub_image": "I", "roi": [10, 20, 64, 64],
                       "axis": "x", "direction": "along_track", "angle_deg": 5.01, "mtf50_cy_px": 0.1803,
                       "mtf50_expanded_cy_px": 0.0021, "mtf_nyquist": 0.043},
                      # Found from target T1_x in raw sub-image I and compared with the virtual image
                      # (quality mtf --targets --sub-image I --mapping --virtual-image).
                      {"source": "q/raw_I_targets.json", "image_kind": "raw", "sub_image": "I", "image_id": "0007",
                       "target": "T1_x", "roi": [20, 12, 70, 64], "axis": "x", "direction": "along_track",
                       "mtf50_cy_px": 0.1806, "mtf50_expanded_cy_px": 0.0022, "position_virtual_px": [2100.5, 3300.5],
                       "resampling": {"virtual_mtf50_cy_px": 0.1652, "virtual_mtf50_expanded_cy_px": 0.0021,
                                      "loss_percent": 8.527, "loss_expanded_percent": 1.68,
                                      "predicted_loss_percent": 8.31, "uniform_phase_loss_percent": 7.12}},
                      {"source": "q/virtual_targets.json", "image_kind": "virtual", "image_id": "0007",
                       "target": "T1_y", "axis": "y", "direction": "across_track", "mtf50_cy_px": 0.1690,
                       "position_virtual_px": [9000, 5000]}],
            "virtual_format_px": [14000, 12000],
            "resampling_per_sub_image": [{"sub_image": "I", "axis": "x", "direction": "along_track", "edges": 1,
                                          "raw_mean_mtf50_cy_px": 0.1806, "virtual_measured": 1,
                                          "virtual_mean_mtf50_cy_px": 0.1652, "mean_loss_percent": 8.527,
                                          "mean_predicted_loss_percent": 8.31,
                                          "mean_uniform_phase_loss_percent": 7.12}],
            "axes": [dict(axis, source="q/raw_I.json", image_kind="raw", sub_image="I", mtf50_cy_px=0.1805,
                          mtf50_expanded_cy_px=0.002),
                     dict(axis, source="q/virtual.json", image_kind="virtual", mtf50_cy_px=0.1720,
                          mtf50_expanded_cy_px=0.0038)],
            "resampling_loss": [{"axis": "x", "direction": "along_track", "sub_images": ["I"],
                                 "raw_mean_mtf50_cy_px": 0.1805, "raw_mean_u_cy_px": 0.001, "virtual_results": 1,
                                 "virtual_mtf50_cy_px": 0.1720, "virtual_u_cy_px": 0.0019, "loss_cy_px": 0.0085,
                                 "loss_u_cy_px": 0.00215, "loss_expanded_cy_px": 0.0043, "loss_percent": 4.709,
                                 "loss_expanded_percent": 2.382, "coverage_factor": 2}],
            "bars": [{"source": "q/bars.json", "options": {"gamma": 1, "threshold": 0.1},
                      "limiting_frequency_cy_px": 0.3311, "limit_in_range": True, "limiting_lp_per_mm": 36.79}],
            "stars": []}
        text, page = self.render({"kind": "flight", "schema_version": 2, "dynamic_image_resolution": section})
        self.assertIn("10. Dynamic image resolution", page.headings)
        self.assertIn('<a href="#resolution">', text)
        self.assertEqual(page.row("resolution-axes", "sub-image I")[:5],
                         ["sub-image I", "x", "along_track", "4", "0.1805"])
        self.assertEqual(page.row("resolution-axes", "virtual image")[7], "0.0038")
        self.assertEqual(page.row("resolution-loss", "x"),
                         ["x", "along_track", "I", "0.1805", "0.1720", "0.0085", "0.0043", "4.71", "2.38"])
        self.assertEqual(page.row("resolution-limits", "bar target 1")[:4], ["bar target 1", "0.10", "0.3311", "36.79"])
        self.assertEqual(page.row("resolution-edges", "sub-image I")[1], "10,20,64,64")
        # The map of MTF50 across the format (issue 36 item 3) and the per-sub-image and per-edge tables.
        self.assertIn('id="resolution-map"', text)
        self.assertIn("MTF50 across the format", text)
        self.assertIn("(14000 x 12000 px)", text)
        self.assertEqual(text.count(PNG_URI), 1)
        # On the map, the edge found in raw sub-image I is placed twice at its place in the virtual
        # image: its raw MTF50 among the raw sub-images, and, marked as the virtual image's, the MTF50
        # measured in the virtual image resampled from it (its resampling block); the edge measured in
        # the virtual image directly keeps its panel.
        sys.path.insert(0, os.path.join(HERE, "..", "..", "tools", "report"))
        try:
            import report_resolution
        finally:
            sys.path.pop(0)
        self.assertEqual(report_resolution.map_panels(section), {
            "along track (MTF along x), raw sub-images": [(2100.5, 3300.5, 0.1806)],
            "along track (MTF along x), virtual image": [(2100.5, 3300.5, 0.1652)],
            "across track (MTF along y), virtual image": [(9000.0, 5000.0, 0.1690)]})
        self.assertIn("the virtual image's panel holds the same edges measured in the virtual image", text)
        self.assertEqual(page.row("resolution-subimages", "I"),
                         ["I", "x", "along_track", "1", "0.1806", "1", "0.1652", "8.53", "8.31", "7.12"])
        self.assertEqual(page.row("resolution-pairs", "I"),
                         ["I", "0007", "T1_x", "along_track", "0.1806", "0.0022", "0.1652", "0.0021", "8.53", "1.68",
                          "8.31", "7.12"])
        # Without --quality the section and its entry in the contents are absent.
        text, page = self.render({"kind": "flight", "schema_version": 2})
        self.assertNotIn("Dynamic image resolution", text)


class CertificateHeads(unittest.TestCase):
    """tools/certificate/aerocal_certificate.py draws and budgets every head of a rig's certificate
    (its `heads`, computed by aerocal), not only the first: one budget table, one distortion row and
    one correlation map per head, each from that head's own numbers."""

    @classmethod
    def setUpClass(cls):
        import importlib.util
        path = os.path.join(HERE, "..", "..", "tools", "certificate", "aerocal_certificate.py")
        spec = importlib.util.spec_from_file_location("aerocal_certificate", path)
        cls.cert = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(cls.cert)

    @staticmethod
    def certificate(heads):
        # Exported numbers as certificate.json holds them (head k's curve scaled by k + 1, so each
        # panel's line tells which head's samples it drew).
        units = [{"id": h,
                  "distortion": {"profile_kind": "10-parameter terms",
                                 "profile": [[r, (k + 1) * 0.1 * r, 0.01 * r] for r in range(0, 31, 10)],
                                 "grid": [[x, y, (k + 1) * 0.1, -0.1] for x in (-10, 10) for y in (-5, 5)]},
                  "correlation": {"names": ["c", "x0"], "covariance": [[1e-6, 0], [0, 1e-6]],
                                  "correlation": [[1.0, 0.1 * k], [0.1 * k, 1.0]]}}
                 for k, h in enumerate(heads)]
        rows = [{"quantity": "%s.dr@20" % h, "value": 2.0 * (k + 1), "U": 0.3 * (k + 1), "k": 2.0,
                 "u_c": 0.15 * (k + 1), "dof_eff": 500.0 + k, "unit": "um",
                 "components": [{"source": "image measurements", "type": "A", "distribution": "normal",
                                 "u": 0.15 * (k + 1), "dof": 500.0 + k}]}
                for k, h in enumerate(heads)]
        for k, h in enumerate(heads):
            units[k].update(results=[rows[k]], radii_mm=[20.0 - k])
        m_0 = {"quantity": "m_0", "value": 0.3, "U": 0.02, "k": 2.0, "u_c": 0.01, "dof_eff": 900.0,
               "unit": "um", "components": [{"source": "variance estimate", "type": "A",
                                             "distribution": "normal", "u": 0.01, "dof": 900.0}]}
        return {"camera_file": {"format_px": [6000, 4000]}, "residuals": [[100, 100, 0.5, -0.2]],
                "results": rows[:1] + [m_0] + rows[1:],
                "distortion": units[0]["distortion"], "correlation": units[0]["correlation"],
                "heads": units}

    def titles(self, fig):
        return [ax.get_title() for ax in fig.axes if ax.get_title()]

    def test_four_heads_give_four_distortion_rows_and_four_correlation_maps(self):
        heads = ["A", "B", "C", "D"]
        c = self.certificate(heads)
        fig = self.cert.fig_distortion(c)
        titles = self.titles(fig)
        for k, h in enumerate(heads):
            self.assertIn("head %s: distortion curves (bars: U, k as stated)" % h, titles)
            self.assertIn("head %s: correction dx, dy over the format" % h, titles)
            ax = next(a for a in fig.axes if a.get_title().startswith("head %s: distortion" % h))
            # The radial curve is the head's own samples, and its certified point is its own row.
            self.assertEqual(list(ax.lines[0].get_ydata()), [(k + 1) * 0.1 * r for r in range(0, 31, 10)])
            self.assertTrue(any(list(line.get_ydata()) == [2.0 * (k + 1)] for line in ax.lines))
        self.assertEqual(sum(t.endswith("distortion curves (bars: U, k as stated)") for t in titles), 4)
        self.cert.plt.close(fig)
        fig = self.cert.fig_residuals_correlation(c)
        titles = self.titles(fig)
        maps = [t for t in titles if t.endswith("correlation of the interior parameters")]
        self.assertEqual(maps, ["head %s: correlation of the interior parameters" % h for h in heads])
        for k, h in enumerate(heads):
            ax = next(a for a in fig.axes if a.get_title() == maps[k])
            self.assertAlmostEqual(ax.images[0].get_array()[0][1], 0.1 * k)
        self.cert.plt.close(fig)

    def test_every_head_gets_its_own_budget_table(self):
        # One table per head from its own rows (its U, nu), at its own radii, then m_0 (one
        # adjustment of all heads) apart; a single camera keeps one table of all its rows.
        heads = ["A", "B", "C"]
        tables = self.cert.budget_tables(self.certificate(heads))
        self.assertEqual([t for t, _ in tables], ["head A (radii 20 mm)", "head B (radii 19 mm)",
                                                  "head C (radii 18 mm)", "the adjustment of all heads"])
        for k, h in enumerate(heads):
            rows = tables[k][1]
            self.assertEqual([r[0] for r in rows[1:]], ["%s.dr@20" % h] * 2)
            self.assertEqual(rows[2][4], self.cert.fmt(0.15 * (k + 1), 3) + " / " + self.cert.fmt_u(0.3 * (k + 1)))
            self.assertEqual(rows[1][5], self.cert.fmt(500.0 + k, 3))
        self.assertEqual([r[0] for r in tables[3][1][1:]], ["m_0", "m_0"])
        c = self.certificate(["A"])
        del c["heads"]
        self.assertEqual([t for t, _ in self.cert.budget_tables(c)], [""])
        self.assertEqual(len(self.cert.budget_tables(c)[0][1]), 1 + 2 * len(c["results"]))

    def test_a_single_camera_keeps_one_row(self):
        c = self.certificate(["A"])
        del c["heads"]
        c["results"] = [{"quantity": "dr@20", "value": 2.0, "U": 0.3}]
        fig = self.cert.fig_distortion(c)
        self.assertEqual(self.titles(fig), ["distortion curves (bars: U, k as stated)",
                                            "correction dx, dy over the format"])
        self.cert.plt.close(fig)
        fig = self.cert.fig_residuals_correlation(c)
        self.assertIn("correlation of the interior parameters", self.titles(fig))
        self.cert.plt.close(fig)


if __name__ == "__main__":
    unittest.main()
