"""Tolerant reading of the `aerocal flight` result document (docs/formats.md "Result documents").

Every accessor returns plain Python values or None when a key is absent, so that a missing section
is shown as "not available" instead of stopping the report. Only keys of the result's schema
(docs/schema/flight.schema.json, adjust.schema.json, stitch.schema.json) are read, in the writers'
spelling: tests/tools/schema_keys_test.py records every key the report looks up and fails on one
the schema does not list.
"""
import csv
import hashlib
import io
import json
import math
import os

# The 10-parameter model's table (CONVENTIONS.md): name, unit.
INTERIOR_PARAMETERS = [("c", "mm"), ("x0", "mm"), ("y0", "mm"), ("K1", "mm^-2"), ("K2", "mm^-4"),
                       ("K3", "mm^-6"), ("P1", "mm^-1"), ("P2", "mm^-1"), ("B1", "1"), ("B2", "1")]

ADJUSTMENT_TITLES = {"conventional": "Conventional triangulation",
                     "self_calibration": "Self-calibrating triangulation",
                     "joint": "Joint adjustment (stitching and triangulation)"}


# ResultSchemaVersion of calib/core/result_file.h: the version of each kind this reader understands.
SCHEMA_VERSIONS = {"flight": 2, "adjust": 3}


class InputError(Exception):
    """The input is not a flight result; the message names the file and the rule."""


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror})")
    try:
        doc = json.loads(text)
    except ValueError as e:
        raise InputError(f"{path}: not a JSON document ({e})")
    if not isinstance(doc, dict):
        raise InputError(f"{path}: not a flight result (top level is not an object)")
    if doc.get("kind") not in ("flight", "adjust"):
        raise InputError(f"{path}: not a flight or adjust result (kind is {json.dumps(doc.get('kind'))}, "
                         f"expected \"flight\" or \"adjust\")")
    expected = SCHEMA_VERSIONS[doc["kind"]]
    if doc.get("schema_version") != expected or isinstance(doc.get("schema_version"), bool):
        raise InputError(f"{path}: schema_version is {json.dumps(doc.get('schema_version'))}, "
                         f"expected {expected} (kind {json.dumps(doc.get('kind'))})")
    if doc["kind"] == "adjust":
        return as_flight_document(doc)
    inflate_residual_tables(doc, path)  # `flight --residuals-csv`: only a flight writes them
    return doc


# The columns of a residuals_<adjustment>.csv (tools/observation_tables.h, the writer's table):
# CSV name, JSON key, element of a pair (None: the value itself), type, whether the key exists only
# for a tested observation (group_size filled).
RESIDUAL_COLUMNS = [("image", "image", None, str, False), ("point", "point", None, str, False),
                    ("col", "col", None, float, False), ("row", "row", None, float, False),
                    ("v_col_px", "v_col_px", None, float, False), ("v_row_px", "v_row_px", None, float, False),
                    ("sigma_px", "sigma_px", None, float, False), ("used", "used", None, bool, False),
                    ("subimage", "subimage", None, str, False), ("u", "u", None, float, False),
                    ("v", "v", None, float, False), ("head", "head", None, str, False),
                    ("group_size", "group_size", None, int, True), ("verdict", "verdict", None, str, True),
                    ("r_x", "r", 0, float, True), ("r_y", "r", 1, float, True),
                    ("w_x", "w_xy", 0, float, True), ("w_y", "w_xy", 1, float, True),
                    ("mdb_sigma_x", "mdb_sigma", 0, float, True), ("mdb_sigma_y", "mdb_sigma", 1, float, True),
                    ("mdb_px_x", "mdb_px", 0, float, True), ("mdb_px_y", "mdb_px", 1, float, True),
                    ("reason", "reason", None, str, False)]


# The columns of residuals_stitching.csv (the stitching frames' residuals, each row with its frame's
# id): always written, an empty sigma_px is a null.
STITCHING_RESIDUAL_COLUMNS = [("frame", "frame", None, str, False), ("point", "point", None, str, False),
                              ("subimage", "subimage", None, str, False), ("kind", "kind", None, str, False),
                              ("vU_px", "vU_px", None, float, False), ("vV_px", "vV_px", None, float, False),
                              ("sigma_px", "sigma_px", None, float, False)]


def residual_rows(text, where, columns=RESIDUAL_COLUMNS):
    """The residual entries of a residual table's text (`columns`: RESIDUAL_COLUMNS for
    residuals_<adjustment>.csv, STITCHING_RESIDUAL_COLUMNS), as the result's JSON held them."""
    reader = csv.reader(io.StringIO(text, newline=""))
    header = next(reader, None)
    names = [c[0] for c in columns]
    stitching = columns is STITCHING_RESIDUAL_COLUMNS
    if header != names:
        raise InputError(f"{where}:1: not a residual table (expected the header {','.join(names)})")
    out = []
    for fields in reader:
        if not fields:
            continue
        if len(fields) != len(names):
            raise InputError(f"{where}:{reader.line_num}: {len(fields)} fields (expected {len(names)})")
        tested = not stitching and fields[12] != ""  # group_size: the test's keys are there
        entry = {}
        for (name, key, element, kind, only_tested), f in zip(columns, fields):
            if only_tested and not tested:
                continue
            try:
                value = (None if f == "" and kind is not str else (f == "true") if kind is bool
                         else kind(float(f)) if kind is int else kind(f))
            except ValueError:
                raise InputError(f"{where}:{reader.line_num}: {name} is not a number ({f!r})")
            if element is not None:
                entry.setdefault(key, [None, None])[element] = value if f != "" else None
            elif f != "" or (only_tested and kind is str) or stitching:
                entry[key] = value
        out.append(entry)
    return out


def _table_text(spec, path):
    """The text of the table a `residuals_file` names, beside the result, SHA-256 checked."""
    table = os.path.join(os.path.dirname(path), str(spec.get("path")))
    try:
        with open(table, "rb") as f:
            data = f.read()
    except OSError as e:
        raise InputError(f"{table}: cannot read the residual table {path} names ({e.strerror})")
    if hashlib.sha256(data).hexdigest() != spec.get("sha256"):
        raise InputError(f"{table}: SHA-256 differs from the one {path} states")
    return table, data.decode("utf-8")


def inflate_residual_tables(doc, path):
    """`flight --residuals-csv`: each adjustment's `residuals_file` and the stitching's read back
    (beside the result, SHA-256 checked) into their `residuals`, so every reader sees one document."""
    for a in doc.get("adjustments") or []:
        spec = a.get("residuals_file") if isinstance(a, dict) else None
        if not isinstance(spec, dict):
            continue
        table, text = _table_text(spec, path)
        a["residuals"] = residual_rows(text, table)
        del a["residuals_file"]
    stitching = doc.get("stitching")
    spec = stitching.get("residuals_file") if isinstance(stitching, dict) else None
    if isinstance(spec, dict):
        table, text = _table_text(spec, path)
        frames = [f for f in stitching.get("frames") or [] if isinstance(f, dict)]
        for f in frames:
            f["residuals"] = []
        k = 0
        for row, entry in enumerate(residual_rows(text, table, STITCHING_RESIDUAL_COLUMNS), start=2):
            # Rows are in the frames' order, a frame's rows together (observation_tables.cc).
            while k < len(frames) and frames[k].get("frame") != entry["frame"]:
                k += 1
            if k == len(frames):
                raise InputError(f"{table}:{row}: frame {entry['frame']!r} is not a frame of {path} "
                                 "after the previous row's (rows are in the frames' order)")
            del entry["frame"]
            frames[k]["residuals"].append(entry)
        del stitching["residuals_file"]


def as_flight_document(doc):
    """An `aerocal adjust` result in the flight document's layout: its adjustment (and with
    --compare the conventional reference run, `conventional`) as `adjustments`, the project facts
    (`inputs`, `camera_format`, `camera_names`, `frame`, `camera_written_from`) at the top."""
    own = dict(doc)
    own["name"] = "self_calibration" if listing(doc.get("self_calibration")) else "conventional"
    adjustments = []
    if isinstance(doc.get("conventional"), dict):
        reference = dict(doc["conventional"])
        reference["name"] = "conventional"
        adjustments.append(reference)
        own.pop("conventional")
    adjustments.append(own)
    out = {k: doc.get(k) for k in ("kind", "schema_version", "aerocal_version", "inputs", "camera_format",
                                   "camera_names", "frame", "camera_written_from", "project", "valid",
                                   "camera_model") if k in doc}
    out["adjustments"] = adjustments
    out["warnings"] = [dict(w, adjustment=own["name"]) for w in listing(doc.get("warnings")) if isinstance(w, dict)]
    return out


def get(obj, *keys):
    """obj[k] for the first k present (dict), else None."""
    if not isinstance(obj, dict):
        return None
    for k in keys:
        if k in obj and obj[k] is not None:
            return obj[k]
    return None


def number(x):
    """A finite float, or None (JSON null, strings, NaN)."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    return float(x) if math.isfinite(x) else None


def listing(x):
    return x if isinstance(x, list) else []


def triple(x):
    """[X, Y, Z] as three numbers or Nones."""
    x = listing(x)
    return [number(x[k]) if k < len(x) else None for k in range(3)]


# ---- stitching ------------------------------------------------------------------------------

def frames(stitching):
    return [f for f in listing(get(stitching, "frames")) if isinstance(f, dict)]


def model_choice(frame):
    return get(frame, "model_choice") or {}


def candidates(frame):
    """Per-model rows of a frame's model comparison: dicts with model, sigma0, sigma0_px,
    redundancy, determinable, refusal and test (dict: against, F, F_critical, p_value, significant)."""
    rows = []
    for c in listing(get(model_choice(frame), "table")):
        if not isinstance(c, dict) or not isinstance(c.get("model"), str):
            continue
        test = c.get("test") if isinstance(c.get("test"), dict) else None  # the first has none
        rows.append({"model": c["model"], "sigma0": number(c.get("sigma0")),
                     "sigma0_px": number(c.get("sigma0_px")), "redundancy": number(c.get("redundancy")),
                     "determinable": c.get("determinable", True) is not False,
                     "refusal": c.get("refusal"), "test": test})
    return rows


def stability_models(stitching):
    """Per-model flight stability entries (model, n_frames, mean/std sigma0[_px], flagged, parameters)."""
    stability = get(stitching, "stability") or {}
    out = []
    for m in listing(get(stability, "models")):
        if isinstance(m, dict) and isinstance(m.get("model"), str):
            out.append(m)
    return out


def flagged(entry):
    """[(frame, [reasons])] of a stability entry's {frame, reasons} list."""
    out = []
    for f in listing(get(entry, "flagged")):
        if isinstance(f, dict):
            out.append((str(f.get("frame", "?")), [str(r) for r in listing(f.get("reasons"))]))
    return out


def flags_by_frame(stitching):
    """{frame: [models whose stability test flags it]}."""
    out = {}
    for m in stability_models(stitching):
        for f, _ in flagged(m):
            out.setdefault(f, []).append(m["model"])
    return out


# ---- adjustments ----------------------------------------------------------------------------

def adjustments(doc):
    out = []
    for k, a in enumerate(listing(doc.get("adjustments"))):
        if isinstance(a, dict):
            a = dict(a)
            a.setdefault("name", f"adjustment_{k + 1}")
            out.append(a)
    return out


def title(adjustment):
    name = str(adjustment.get("name"))
    return ADJUSTMENT_TITLES.get(name, name.replace("_", " ").capitalize())


def point_statistics(adjustment, which):
    """control/check statistics with all keys normalised; None when absent."""
    s = get(adjustment, which)
    if not isinstance(s, dict):
        return None
    rmse = triple(s.get("rmse_m"))
    plan = number(s.get("planimetric_rmse_m"))  # C++ exports every figure: none is recomputed here
    spatial = number(s.get("spatial_rmse_m"))
    return {"n": number(s.get("n")), "rmse": rmse, "plan": plan, "spatial": spatial,
            "mean": triple(s.get("mean_m")), "max": triple(s.get("max_abs_m"))}


def point_errors(adjustment, which):
    """[(point, X, Y, Z, dX, dY, dZ)] of control or check points with usable numbers."""
    out = []
    for p in listing(get(get(adjustment, which), "points")):
        if not isinstance(p, dict):
            continue
        xyz, d = triple(p.get("surveyed")), triple(p.get("difference_m"))
        if None in xyz[:2] or None in d:
            continue
        out.append((str(p.get("point", "")), xyz[0], xyz[1], xyz[2], d[0], d[1], d[2]))
    return out


def residuals(adjustment):
    """[(col, row, v_col_px, v_row_px)] image residuals in the image's pixel frame, of the
    observations the adjustment USED (a rejected blunder is listed apart, never plotted)."""
    out = []
    for r in listing(adjustment.get("residuals")):
        if not isinstance(r, dict) or r.get("used") is False:
            continue
        v = [number(get(r, "col")), number(get(r, "row")),
             number(get(r, "v_col_px")), number(get(r, "v_row_px"))]
        if None not in v:
            out.append(tuple(v))
    return out


def cameras(adjustment):
    return [c for c in listing(adjustment.get("cameras")) if isinstance(c, dict)]


def interior_parameters(doc):
    """[(name, unit)] of the camera model's parameter table in the result (`camera_model`,
    calib/README "Result documents"); the 10-parameter table when the result has none."""
    table = [p for p in listing(get(doc.get("camera_model"), "parameters")) if isinstance(p, dict)]
    named = [(str(p.get("name")), str(p.get("unit", ""))) for p in table if p.get("name") is not None]
    return named or INTERIOR_PARAMETERS


def camera_model_name(doc):
    """The camera model's name ("brown_fraser_10" when the result names none)."""
    return str(get(doc.get("camera_model"), "name") or "brown_fraser_10")


def interior(camera, which):
    """{name: value} of 'initial' or 'estimated' with numbers only."""
    block = get(camera, which) or {}
    if not isinstance(block, dict):
        return {}
    return {name: number(v) for name, v in block.items() if number(v) is not None}


def estimates_interior(adjustment):
    """True when the adjustment estimated interior parameters (self-calibration)."""
    if listing(adjustment.get("self_calibration")):
        return True
    return any(listing(c.get("free")) or (isinstance(c.get("sigma"), dict) and c["sigma"])
               for c in cameras(adjustment))


def camera_format(doc):
    """(width_px, height_px, pixel_size_mm) or None."""
    f = doc.get("camera_format")
    values = [number(get(f, "width_px")), number(get(f, "height_px")), number(get(f, "pixel_size_mm"))]
    if None in values or min(values) <= 0:
        return None
    return tuple(values)
