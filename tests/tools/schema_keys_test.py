"""The Python renderers read only keys the result schemas list (issue 30 item 5).

Each renderer (tools/report/aerocal_report.py, tools/report/aerocal_tables.py,
tools/report/rig_error_plots.py, tools/certificate/aerocal_certificate.py) runs in this process on a result the aerocal binary just
wrote, after `aerocal validate` accepted that result against docs/schema/<kind>.schema.json. The
document it loads is wrapped so that every key it looks up (`d[k]`, `d.get(k)`, `k in d`) is
recorded with its path; each path must be listed by the schema (a property, or a key of a map
whose values the schema describes). A key the renderer reads that the writer does not document
fails here, as does a renderer still reading an old spelling. (A renderer's own copy of a
document, e.g. `dict(doc)`, is a plain dict whose top-level lookups are not recorded; the nested
objects stay recorded.)

Run by ctest as tools/schema_keys (tests/tools/report.cmake) with AEROCAL_BINARY set.
"""
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
SCHEMAS = os.path.join(ROOT, "docs", "schema")
BINARY = os.environ.get("AEROCAL_BINARY", os.path.join(ROOT, "build", "tools", "aerocal"))
CONFIGS = os.path.join(ROOT, "configs")
ITEM = "[]"


class TrackedDict(dict):
    """A JSON object that records the path of every key looked up."""

    def __init__(self, value, path, log):
        super().__init__({k: track(v, path + (k,), log) for k, v in value.items()})
        self._path, self._log = path, log

    def __getitem__(self, key):
        self._log.add(self._path + (key,))
        return super().__getitem__(key)

    def get(self, key, default=None):
        self._log.add(self._path + (key,))
        return super().get(key, default)

    def __contains__(self, key):
        self._log.add(self._path + (key,))
        return super().__contains__(key)


def track(value, path, log):
    if isinstance(value, dict):
        return TrackedDict(value, path, log)
    if isinstance(value, list):
        return [track(v, path + (ITEM,), log) for v in value]
    return value


class Schemas:
    """The schema files of docs/schema, with their references resolved file by file."""

    def __init__(self):
        self.files = {}
        for f in os.listdir(SCHEMAS):
            if f.endswith(".json"):
                with open(os.path.join(SCHEMAS, f), encoding="utf-8") as text:
                    self.files[f] = json.load(text)

    def resolve(self, schema, file):
        """(schema, file) with a $ref followed (FILE, FILE#/definitions/N, #/definitions/N, #)."""
        while isinstance(schema, dict) and "$ref" in schema:
            target, _, fragment = schema["$ref"].partition("#")
            file = target or file
            schema = self.files[file]
            if fragment.startswith("/definitions/"):
                schema = schema["definitions"][fragment[len("/definitions/"):]]
        return schema, file

    def branches(self, schema, file):
        """The schema and its allOf parts, each resolved."""
        schema, file = self.resolve(schema, file)
        out = [(schema, file)]
        for part in schema.get("allOf", []) if isinstance(schema, dict) else []:
            out += self.branches(part, file)
        return out

    def step(self, schema, file, key):
        """The schemas of `key` (a property name or ITEM) under `schema`; [] when not listed."""
        out = []
        for s, f in self.branches(schema, file):
            if not isinstance(s, dict):
                continue
            if key == ITEM:
                if "items" in s:
                    out.append((s["items"], f))
            elif key in s.get("properties", {}):
                out.append((s["properties"][key], f))
            elif isinstance(s.get("additionalProperties"), dict):  # a map: any key
                out.append((s["additionalProperties"], f))
        return out

    def unlisted(self, kind, paths):
        """The paths of `paths` the schema of `kind` does not list."""
        missing = []
        for path in sorted(paths, key=lambda p: [str(k) for k in p]):
            here = [(self.files[kind + ".schema.json"], kind + ".schema.json")]
            for key in path:
                here = [n for s, f in here for n in self.step(s, f, key)]
                if not here:
                    missing.append(".".join(str(k) for k in path))
                    break
        return missing


@contextlib.contextmanager
def recording(document_path, log):
    """json.load / json.loads return the document at `document_path` tracked into `log`."""
    load, loads = json.load, json.loads

    def tracked_load(f, *args, **kwargs):
        value = load(f, *args, **kwargs)
        same = os.path.abspath(getattr(f, "name", "")) == os.path.abspath(document_path)
        return track(value, (), log) if same else value

    def tracked_loads(text, *args, **kwargs):
        value = loads(text, *args, **kwargs)
        with open(document_path, encoding="utf-8") as f:
            same = isinstance(text, str) and text == f.read()
        return track(value, (), log) if same else value

    json.load, json.loads = tracked_load, tracked_loads
    try:
        yield
    finally:
        json.load, json.loads = load, loads


def aerocal(*args):
    run = subprocess.run([BINARY] + list(args), capture_output=True, text=True, timeout=600)
    return run.returncode, run.stdout + run.stderr


def run_script(path, argv):
    """main(argv) of the renderer script at `path`, imported fresh, its output swallowed."""
    folder = os.path.dirname(path)
    sys.path.insert(0, folder)
    try:
        name = os.path.splitext(os.path.basename(path))[0]
        spec = __import__("importlib.util").util.spec_from_file_location(name, path)
        module = __import__("importlib.util").util.module_from_spec(spec)
        spec.loader.exec_module(module)
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            code = module.main([path] + argv)
        return code, err.getvalue()
    finally:
        sys.path.remove(folder)


class RenderersReadOnlySchemaKeys(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="aerocal_schema_keys")
        cls.dir = cls.tmp.name
        cls.schemas = Schemas()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def file(self, name):
        return os.path.join(self.dir, name)

    def check(self, kind, result, script, argv):
        code, out = aerocal("validate", result)
        self.assertEqual(code, 0, out)
        log = set()
        with recording(result, log):
            code, err = run_script(script, argv)
        self.assertEqual(code, 0, err)
        self.assertTrue(log, "the renderer read nothing through json.load(s)")
        self.assertEqual(self.schemas.unlisted(kind, log), [],
                         f"{os.path.basename(script)} reads keys of a {kind} result that "
                         f"docs/schema/{kind}.schema.json does not list")

    def test_report_of_an_adjust_result(self):
        code, out = aerocal("simulate", "--out", self.file("sim"))
        self.assertEqual(code, 0, out)
        code, out = aerocal("adjust", "--project", self.file("sim/project.yaml"),
                            "--self-calibration", "all", "--out", self.file("adjust.json"))
        self.assertIn(code, (0, 3), out)
        self.check("adjust", self.file("adjust.json"), os.path.join(ROOT, "tools/report/aerocal_report.py"),
                   [self.file("adjust.json"), self.file("report.html")])
        os.makedirs(self.file("tables"))
        self.check("adjust", self.file("adjust.json"), os.path.join(ROOT, "tools/report/aerocal_tables.py"),
                   [self.file("adjust.json"), self.file("tables")])

    def test_certificate_of_a_calibrate_result(self):
        code, out = aerocal("simulate", "--test-field", "--groups", "2", "--images-per-group", "4",
                            "--out", self.file("tf"))
        self.assertEqual(code, 0, out)
        code, out = aerocal("calibrate", "--camera", self.file("tf/camera_nominal.yaml"), "--observations",
                            self.file("tf/observations.csv"), "--points", self.file("tf/points.csv"),
                            "--out", self.file("cal.json"))
        self.assertIn(code, (0, 3), out)
        code, out = aerocal("certificate", "--result", self.file("cal.json"), "--no-render",
                            "--out", self.file("cert"))
        self.assertIn(code, (0, 3), out)
        self.check("certificate", self.file("cert/certificate.json"),
                   os.path.join(ROOT, "tools/certificate/aerocal_certificate.py"),
                   [self.file("cert/certificate.json"), self.file("cert")])

    def test_rig_error_plots(self):
        code, out = aerocal("rig", "error-analysis", "--camera", os.path.join(CONFIGS, "rig_dual_lens.yaml"),
                            "--limits", os.path.join(CONFIGS, "rig_dual_lens_limits.yaml"), "--samples", "50",
                            "--grid", "3", "--out", self.file("error.json"))
        self.assertIn(code, (0, 3), out)
        self.check("rig_error_analysis", self.file("error.json"),
                   os.path.join(ROOT, "tools/report/rig_error_plots.py"), [self.file("error.json")])

    def test_an_unlisted_key_is_found(self):
        log = set()
        doc = track({"kind": "adjust", "sigma0": 1.0, "cameras": [{"id": "a"}]}, (), log)
        doc.get("sigma0"), doc["cameras"][0].get("focal"), "old_name" in doc
        self.assertEqual(self.schemas.unlisted("adjust", log), ["cameras.[].focal", "old_name"])


if __name__ == "__main__":
    unittest.main()
