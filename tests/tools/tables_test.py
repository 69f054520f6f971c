"""`aerocal export --tables DIR` read back as a spreadsheet and a GIS would (issue 33 item 3):
csv (and pandas when installed) for the CSV files, json for the GeoJSON (QGIS reads the legacy
`crs` member of a projected CRS through GDAL; RFC 7946 coordinates are WGS 84 only).

Run by ctest as tools/tables (tests/tools/report_outputs.cmake), or from tests/tools:
  python3 -m unittest -v tables_test
"""
import csv
import json
import math
import os
import tempfile
import unittest

import aerocal_runs as runs

try:
    import pandas
except ImportError:  # optional: the csv module reads every file too
    pandas = None

TABLES = ["exposures.csv", "points.csv", "point_errors.csv", "residuals.csv", "camera.csv",
          "camera_correlations.csv", "point_errors.geojson"]


def rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def value(text):
    """A CSV cell as a number; '' (unknown) as None, never 0."""
    return None if text == "" else float(text)


class FlightTables(unittest.TestCase):
    """The report fixture (a flight result of three adjustments)."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.tmp.name, "tables")
        runs.aerocal("export", "--result", runs.FIXTURE, "--tables", cls.out)
        with open(runs.FIXTURE) as f:
            cls.doc = json.load(f)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_one_folder_per_adjustment_with_every_table(self):
        names = [a["name"] for a in self.doc["adjustments"]]
        self.assertEqual(sorted(os.listdir(self.out)), sorted(names))
        for name in names:
            self.assertEqual(sorted(os.listdir(os.path.join(self.out, name))), sorted(TABLES))

    def test_residuals_equal_the_result(self):
        for a in self.doc["adjustments"]:
            table = rows(os.path.join(self.out, a["name"], "residuals.csv"))
            self.assertEqual(len(table), len(a["residuals"]))
            for row, r in zip(table, a["residuals"]):
                self.assertEqual((row["image"], row["point"]), (r["image"], r["point"]))
                self.assertEqual(value(row["v_col_px"]), r["v_col_px"])  # shortest round-trip text
                self.assertEqual(value(row["row"]), r["row"])

    def test_camera_parameters_with_sigmas_in_the_model_order(self):
        a = next(a for a in self.doc["adjustments"] if a["name"] == "self_calibration")
        table = rows(os.path.join(self.out, "self_calibration", "camera.csv"))
        self.assertEqual([r["parameter"] for r in table][:3], ["c", "x0", "y0"])
        camera = a["cameras"][0]
        for r in table:
            self.assertEqual(value(r["estimated"]), camera["estimated"][r["parameter"]])
            sigma = camera.get("sigma", {}).get(r["parameter"])
            self.assertEqual(value(r["sigma"]), sigma)  # held parameters: empty, never 0
            self.assertEqual(r["free"], "true" if sigma is not None else "false")

    def test_pandas_reads_every_csv(self):
        if pandas is None:
            self.skipTest("pandas is not installed (the csv module read the files)")
        for name in TABLES[:-1]:
            frame = pandas.read_csv(os.path.join(self.out, "self_calibration", name))
            self.assertGreater(len(frame.columns), 1, name)


class BadInput(unittest.TestCase):
    def test_a_result_of_another_kind_is_exit_2_and_writes_nothing(self):
        with tempfile.TemporaryDirectory() as tmp:
            other = os.path.join(tmp, "stitch.json")
            with open(other, "w") as f:
                json.dump({"kind": "stitch", "schema_version": 2}, f)
            out = os.path.join(tmp, "tables")
            r = runs.aerocal("export", "--result", other, "--tables", out, ok=(2,))
            self.assertIn("stitch.json", r.stderr)
            self.assertFalse(os.path.exists(out) and os.listdir(out))

    def test_tables_and_write_crs_exclude_each_other(self):
        r = runs.aerocal("export", "--result", runs.FIXTURE, "--tables", "t", "--write-crs", "EPSG:4326", "--out", "o",
                         ok=(2,))
        self.assertIn("--tables", r.stderr + r.stdout)


class OdmTables(unittest.TestCase):
    """The real ODM block in WGS 84 / UTM 22S: the GeoJSON in the project's CRS."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        block = runs.odm_block(cls.tmp.name)
        if block is None:
            raise unittest.SkipTest("../shared/data/odm_br_uav_gcp_block is absent")
        cls.project, cls.result = block
        cls.out = os.path.join(cls.tmp.name, "tables")
        runs.aerocal("export", "--project", cls.project, "--result", cls.result, "--tables", cls.out)
        with open(cls.result) as f:
            cls.doc = json.load(f)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_geojson_in_the_projected_crs_with_the_legacy_member(self):
        with open(os.path.join(self.out, "self_calibration", "point_errors.geojson")) as f:
            g = json.load(f)
        self.assertEqual(g["type"], "FeatureCollection")
        self.assertEqual(g["crs"], {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32722"}})
        check = {p["point"]: p for p in self.doc["check"]["points"]}
        features = [f for f in g["features"] if f["properties"]["role"] == "check"]
        self.assertEqual(len(features), len(check))
        for f in features:
            p = check[f["properties"]["point"]]
            self.assertEqual(f["geometry"]["coordinates"], p["adjusted"])  # UTM easting, northing, height
            self.assertAlmostEqual(f["properties"]["d_m"], math.sqrt(sum(d * d for d in p["difference_m"])), 12)

    def test_rejected_observations_are_marked_not_used(self):
        table = rows(os.path.join(self.out, "self_calibration", "residuals.csv"))
        unused = {(r["image"], r["point"]) for r in table if r["used"] == "false"}
        rejected = {(r["image"], r["point"]) for r in self.doc["rejected"]}
        self.assertEqual(unused, rejected)
        self.assertTrue(rejected)  # the two gross errors of the list (PROVENANCE.md)

    def test_exposures_with_sigmas_and_left_out_images(self):
        table = rows(os.path.join(self.out, "self_calibration", "exposures.csv"))
        self.assertEqual(len(table), len(self.doc["exposures"]))
        for row, e in zip(table, self.doc["exposures"]):
            self.assertEqual(row["used"], "true" if e["used"] else "false")
            self.assertEqual(value(row["sZ_m"]), e["sigma"]["Z"])  # null (left out) stays empty
        used = [r for r in table if r["used"] == "true"]
        self.assertTrue(all(int(r["n_used"]) > 0 and value(r["rms_px"]) > 0 for r in used))

    def test_correlations_only_between_estimated_parameters(self):
        table = rows(os.path.join(self.out, "self_calibration", "camera_correlations.csv"))
        free = {f"camera cam1.{n}" for n in self.doc["cameras"][0]["free"]}
        for r in table:
            for other, text in r.items():
                if other == "parameter":
                    continue
                self.assertEqual(text != "", r["parameter"] in free and other in free)
                if r["parameter"] == other and text:
                    self.assertEqual(value(text), 1.0)


if __name__ == "__main__":
    unittest.main()
