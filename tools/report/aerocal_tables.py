#!/usr/bin/python3
"""Writes the tables of an `aerocal adjust` or `aerocal flight` result as CSV and GeoJSON.

Usage: aerocal_tables.py RESULT_JSON OUT_DIR [CRS]

For spreadsheets and GIS (issue 33 item 3); `aerocal export --tables DIR` runs it. One folder per
adjustment of the result (OUT_DIR/<name>/: conventional, self_calibration, joint), each with

  exposures.csv            image, used, X, Y, Z, omega_deg, phi_deg, kappa_deg, and their sigmas
                           (sX_m ... skappa_deg), n_used, rms_px (the used observations of the image)
  points.csv               point, role, rays, X, Y, Z adjusted, X_surveyed .. Z_surveyed, sX_m, sY_m,
                           sZ_m (the adjusted point's sigmas: empty where the result states none)
  point_errors.csv         point, role, rays, dX_m, dY_m, dZ_m, d_plan_m, d_m, w, status, reason
  residuals.csv            image, point, col, row, sigma_px, v_col_px, v_row_px, r_x, r_y, w_x, w_y,
                           mdb_x_px, mdb_y_px, used, verdict (one row per image observation)
  camera.csv               camera, parameter, unit, initial, estimated, sigma, free
  camera_correlations.csv  parameter, then one column per parameter (empty where either is held)
  point_errors.geojson     control and check points at their adjusted position with their errors

Numbers are written as the shortest text that reads back to the same double; an empty cell is an unknown value (JSON null), never a zero. The GeoJSON's
coordinates are in the result's CRS (CRS: an EPSG code such as EPSG:32722, given by `aerocal
export` from the project's `frame: {crs: ...}`); for a projected CRS it carries the GeoJSON 2008
`crs` member ({"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32722"}}), which GDAL
and so QGIS read, since RFC 7946 allows WGS 84 longitude / latitude only (`aerocal export
--write-crs EPSG:4326` writes that form). Without a CRS the coordinates are the local frame's.
Exit 0 on success, 2 with one line "error: ..." when the input is not such a result (nothing
written). Every file is written to a temporary name and renamed.
"""
import csv
import io
import json
import os
import re
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report_data as rd  # noqa: E402  (after the path is set)
import report_points as rp  # noqa: E402

AXES = ("X", "Y", "Z")
ANGLES = ("omega", "phi", "kappa")


def cell(x):
    """A number as the shortest text that reads back to the same double, '' for null / absent /
    not finite."""
    if isinstance(x, bool):
        return "true" if x else "false"
    v = rd.number(x)
    if v is None:
        return ""
    return str(int(v)) if isinstance(x, int) else repr(v)


def csv_text(header, rows):
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return buffer.getvalue()


def exposures(a):
    rms = rp.image_rms(a)
    rows = []
    for e in rd.listing(a.get("exposures")):
        if not isinstance(e, dict):
            continue
        sigma = e.get("sigma") if isinstance(e.get("sigma"), dict) else {}
        n, v = rms.get(str(e.get("image")), (0, None))
        rows.append([e.get("image", ""), cell(e.get("used", True))] + [cell(e.get(k)) for k in AXES + ANGLES] +
                    [cell(sigma.get(k)) for k in AXES + ANGLES] + [n, cell(v)])
    return csv_text(["image", "used", "X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg", "sX_m", "sY_m", "sZ_m",
                     "somega_deg", "sphi_deg", "skappa_deg", "n_used", "rms_px"], rows)


def _points(a):
    """(role, point dict) of every control and check point of the adjustment."""
    out = []
    for role in ("control", "check"):
        for p in rd.listing(rd.get(rd.get(a, role), "points")):
            if isinstance(p, dict):
                out.append((role, p))
    for p in rd.listing(a.get("control_left_out")):
        if isinstance(p, dict):
            out.append(("control (survey left out)", dict(p, adjusted=p.get("adjusted_m"), surveyed=p.get("surveyed_m"))))
    return out


def points(a):
    rows = []
    for role, p in _points(a):
        adjusted, surveyed = rd.triple(p.get("adjusted")), rd.triple(p.get("surveyed"))
        rows.append([p.get("point", ""), role, cell(p.get("rays"))] + [cell(v) for v in adjusted] +
                    [cell(v) for v in surveyed])
    # No sigma columns: an adjust result holds no sigmas of the control and check points.
    return csv_text(["point", "role", "rays", "X", "Y", "Z", "X_surveyed", "Y_surveyed", "Z_surveyed"], rows)


def point_errors(a):
    rows = []
    for role in ("control", "check"):
        for r in rp.point_rows(a, role):
            rows.append([r["point"], role, cell(r["rays"])] + [cell(v) for v in r["d"]] +
                        [cell(r["plan"]), cell(r["spatial"]), cell(r["w"]), r["status"], r["reason"]])
    return csv_text(["point", "role", "rays", "dX_m", "dY_m", "dZ_m", "d_plan_m", "d_m", "w", "status", "reason"], rows)


def residuals(a):
    rows = []
    for r in rd.listing(a.get("residuals")):
        if not isinstance(r, dict):
            continue
        pair = lambda key: (rd.listing(r.get(key)) + [None, None])[:2]  # noqa: E731
        rows.append([r.get("image", ""), r.get("point", "")] +
                    [cell(r.get(k)) for k in ("col", "row", "sigma_px", "v_col_px", "v_row_px")] +
                    [cell(v) for v in pair("r") + pair("w_xy") + pair("mdb_px")] +
                    [cell(r.get("used", True)), r.get("verdict", "")])
    return csv_text(["image", "point", "col", "row", "sigma_px", "v_col_px", "v_row_px", "r_x", "r_y", "w_x", "w_y",
                     "mdb_x_px", "mdb_y_px", "used", "verdict"], rows)


def camera(doc, a):
    table = rd.interior_parameters(doc)  # the model's order
    rows = []
    for c in rd.cameras(a):
        initial, estimated = rd.interior(c, "initial"), rd.interior(c, "estimated")
        sigma = c.get("sigma") if isinstance(c.get("sigma"), dict) else {}
        for name, unit in table:
            if name in estimated:
                rows.append([c.get("id", ""), name, unit, cell(initial.get(name)), cell(estimated[name]),
                             cell(sigma.get(name)), cell(name in sigma)])
    return csv_text(["camera", "parameter", "unit", "initial", "estimated", "sigma", "free"], rows)


def correlations(a):
    table = a.get("interior_correlation") if isinstance(a.get("interior_correlation"), dict) else {}
    names = [str(n) for n in rd.listing(table.get("names"))]
    matrix = rd.listing(table.get("matrix"))
    free = {f"camera {c.get('id')}.{n}" for c in rd.cameras(a) for n in rd.listing(c.get("free"))}
    rows = []
    for i, name in enumerate(names):
        row = rd.listing(matrix[i]) if i < len(matrix) else []
        rows.append([name] + [cell(row[j]) if j < len(row) and name in free and names[j] in free else ""
                              for j in range(len(names))])
    return csv_text(["parameter"] + names, rows)


def geojson(a, crs):
    features = []
    for role, p in _points(a):
        adjusted = rd.triple(p.get("adjusted"))
        if None in adjusted:
            continue
        r = next((x for x in rp.point_rows(a, role.split(" ")[0]) if x["point"] == p.get("point")), None)
        d = r["d"] if r else [None] * 3
        features.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": adjusted},
                         "properties": {"point": p.get("point"), "role": role, "rays": p.get("rays"),
                                        "dX_m": d[0], "dY_m": d[1], "dZ_m": d[2],
                                        "d_plan_m": r["plan"] if r else None, "d_m": r["spatial"] if r else None,
                                        "status": r["status"] if r else "", "reason": r["reason"] if r else ""}})
    doc = {"type": "FeatureCollection", "name": "point_errors", "features": features}
    epsg = re.fullmatch(r"EPSG:(\d+)", crs or "")
    if epsg:
        doc["crs"] = {"type": "name", "properties": {"name": f"urn:ogc:def:crs:EPSG::{epsg.group(1)}"}}
    return json.dumps(doc, indent=1) + "\n"


def write_atomically(path, text):
    tmp = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.tmp{os.getpid()}")
    with open(tmp, "w", encoding="utf-8", newline="") as f:
        f.write(text)
    os.replace(tmp, path)


def tables(doc, crs):
    """{relative path: text} of every table."""
    out = {}
    for a in rd.adjustments(doc):
        name = re.sub(r"[^A-Za-z0-9_.-]+", "_", str(a["name"]))
        for file, text in (("exposures.csv", exposures(a)), ("points.csv", points(a)),
                           ("point_errors.csv", point_errors(a)), ("residuals.csv", residuals(a)),
                           ("camera.csv", camera(doc, a)), ("camera_correlations.csv", correlations(a)),
                           ("point_errors.geojson", geojson(a, crs))):
            out[os.path.join(name, file)] = text
    return out


def main(argv):
    if len(argv) not in (3, 4):
        sys.stderr.write("error: usage: aerocal_tables.py RESULT_JSON OUT_DIR [CRS]\n")
        return 2
    try:
        doc = rd.load(argv[1])
    except rd.InputError as e:
        sys.stderr.write(f"error: {e}\n")
        return 2
    files = tables(doc, argv[3] if len(argv) == 4 else "")
    try:
        for path, text in files.items():
            full = os.path.join(argv[2], path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            write_atomically(full, text)
    except OSError as e:
        sys.stderr.write(f"error: {argv[2]}: cannot write the tables ({e.strerror})\n")
        return 2
    for path in sorted(files):
        print(os.path.join(argv[2], path))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
