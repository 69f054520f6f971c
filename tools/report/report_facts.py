"""The project facts, the verdict line and the case-dependent advice of the report (issue 33 item 1).

Facts come from the result (`inputs` with their SHA-256, `frame`, `camera_format`, cameras); what
the result does not state is derived here from the adjusted exposures and points and labelled as
derived: flying height above the mean surveyed ground, GSD = pixel x height / c, strips (a new strip
where the heading turns by more than 45 deg or the step exceeds 2.5 times the median step) and
forward / side overlaps of the nadir footprints (1 - base / footprint length along the strip, 1 -
strip spacing / footprint width across it).
"""
import datetime
import math
import os
import statistics

import report_data as rd
from report_html import Cell, esc, fmt, note, num, table, text

NEW_STRIP_TURN_DEG = 45.0   # heading change that starts a new strip
NEW_STRIP_STEP_RATIO = 2.5  # a step this many times the median step starts a new strip
NADIR_LIMIT_DEG = 15.0      # omega and phi below this: a near-vertical (aerial, UAV) image


def _used_exposures(adjustment):
    out = []
    for e in rd.listing(adjustment.get("exposures")):
        if not isinstance(e, dict) or e.get("used") is False:
            continue
        v = [rd.number(e.get(k)) for k in ("X", "Y", "Z", "omega", "phi", "kappa")]
        if None not in v:
            out.append((str(e.get("image", "")),) + tuple(v))
    return out


def _ground_height(adjustment):
    heights = []
    for which in ("control", "check"):
        for p in rd.listing(rd.get(rd.get(adjustment, which), "points")):
            if isinstance(p, dict):
                z = rd.triple(p.get("surveyed"))[2]
                if z is not None:
                    heights.append(z)
    return statistics.mean(heights) if heights else None


def strips(exposures):
    """[[image, ...], ...] in the exposures' order."""
    if len(exposures) < 2:
        return [[e[0] for e in exposures]] if exposures else []
    steps = [math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(exposures, exposures[1:])]
    median = statistics.median(steps) or 1.0
    out, heading = [[exposures[0][0]]], None
    for k, (a, b) in enumerate(zip(exposures, exposures[1:])):
        h = math.degrees(math.atan2(b[2] - a[2], b[1] - a[1]))
        turned = heading is not None and abs((h - heading + 180) % 360 - 180) > NEW_STRIP_TURN_DEG
        if turned or steps[k] > NEW_STRIP_STEP_RATIO * median:
            out.append([])
            heading = None
        else:
            heading = h
        out[-1].append(b[0])
    return out


def geometry(doc, adjustment):
    """Derived flight geometry: dict with height_m, gsd_m, strips, forward, side, aerial; or None."""
    exposures = _used_exposures(adjustment)
    ground = _ground_height(adjustment)
    fmt_info = rd.camera_format(doc)
    cams = rd.cameras(adjustment)
    c_mm = rd.number(rd.interior(cams[0], "estimated").get("c")) if cams else None
    if not exposures or ground is None or not fmt_info or not c_mm:
        return None
    w_px, h_px, pixel_mm = fmt_info
    height = statistics.mean(e[3] for e in exposures) - ground
    aerial = all(abs(e[4]) < NADIR_LIMIT_DEG and abs(e[5]) < NADIR_LIMIT_DEG for e in exposures) and height > 0
    out = {"height_m": height, "gsd_m": pixel_mm * height / c_mm, "aerial": aerial,
           "strips": strips(exposures) if aerial else [], "forward": None, "side": None}
    if not aerial:
        return out
    by_image = {e[0]: e for e in exposures}
    scale = height / c_mm  # metres on the ground per mm in the image
    forward, centres = [], []
    for strip in out["strips"]:
        pts = [by_image[i] for i in strip]
        centres.append((statistics.mean(p[1] for p in pts), statistics.mean(p[2] for p in pts)))
        for a, b in zip(pts, pts[1:]):
            heading = math.atan2(b[2] - a[2], b[1] - a[1])
            # The image x axis points along kappa in the object frame (a nadir image).
            along_x = abs(math.cos(heading - math.radians(a[6]))) > math.sqrt(0.5)
            length = (w_px if along_x else h_px) * pixel_mm * scale
            forward.append(1 - math.hypot(b[1] - a[1], b[2] - a[2]) / length)
    if forward:
        out["forward"] = statistics.mean(forward)
    if len(centres) > 1:
        spacing = statistics.median(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(centres, centres[1:]))
        first = by_image[out["strips"][0][0]]
        second = by_image[out["strips"][0][1]] if len(out["strips"][0]) > 1 else first
        heading = math.atan2(second[2] - first[2], second[1] - first[1])
        along_x = abs(math.cos(heading - math.radians(first[6]))) > math.sqrt(0.5)
        width = (h_px if along_x else w_px) * pixel_mm * scale
        out["side"] = 1 - spacing / width
    return out


def written_utc():
    """The report's date: $SOURCE_DATE_EPOCH when set (reproducible-builds.org: a lab re-running a
    flight gets the same page byte for byte), else now."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "")
    when = (datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc) if epoch.isdigit()
            else datetime.datetime.now(datetime.timezone.utc))
    return when.strftime("%Y-%m-%d %H:%M")


def _main_adjustment(doc):
    adjs = rd.adjustments(doc)
    written = rd.get(doc.get("camera_written_from"), "adjustment")
    return next((a for a in adjs if a.get("name") == written), adjs[-1] if adjs else None)


def facts(doc):
    out = ['<h2 id="project">2. Project</h2>']
    main = _main_adjustment(doc)
    geo = geometry(doc, main) if main else None
    if doc.get("camera_name"):  # a flight: its one camera
        names = {"camera": doc.get("camera_name")}
    else:  # an adjust result: every camera by id
        names = doc.get("camera_names") if isinstance(doc.get("camera_names"), dict) else {}
    cameras = "; ".join(f"{esc(k)}: {esc(v or 'unnamed')}" for k, v in names.items()) or "not available"
    fmt_info = rd.camera_format(doc)
    fmt_text = (f"{int(fmt_info[0])} x {int(fmt_info[1])} px, pixel {fmt_info[2] * 1000:g} um, "
                f"{fmt_info[0] * fmt_info[2]:.1f} x {fmt_info[1] * fmt_info[2]:.1f} mm") if fmt_info else "not available"
    where = ([["camera file", text(doc.get("camera") or "not available")],
              ["data folder", text(doc.get("data") or "not available")]] if doc.get("kind") == "flight" else
             [["project", text(doc.get("project") or "not available")]])
    rows = where + [["image format", text(fmt_text)], ["report written (UTC)", text(written_utc())],
            ["aerocal version", text(doc.get("aerocal_version") or "not available")],
            ["camera(s)", Cell(cameras + " (serial number: not recorded in the camera file)")],
            ["coordinate frame", Cell(esc(doc.get("frame") or "not available"), "text-small")]]
    if geo:
        rows += [["flying height above the mean surveyed ground (derived)", text(f"{geo['height_m']:.1f} m")],
                 ["ground sample distance (derived: pixel x height / c)", text(f"{geo['gsd_m'] * 100:.2f} cm")]]
        if geo["aerial"]:
            sizes = ", ".join(str(len(s)) for s in geo["strips"])
            rows += [["strips (derived from the exposure centres)", text(f"{len(geo['strips'])} ({sizes} exposures)")],
                     ["forward overlap (derived, mean)", text(fmt(geo["forward"] * 100 if geo["forward"] is not None
                                                               else None, ".0f") + " %")],
                     ["side overlap (derived)", text(fmt(geo["side"] * 100 if geo["side"] is not None else None,
                                                         ".0f") + " %")]]
        else:
            rows.append(["geometry", text("not a vertical aerial block (tilted or convergent images): no strips")])
    out.append(table("project-facts", "Project facts", ["item", "value"], rows))
    inputs = [f for f in rd.listing(doc.get("inputs")) if isinstance(f, dict)]
    if inputs:
        out.append(table("project-inputs", "Input files (SHA-256 of the bytes read)", ["role", "file", "bytes", "SHA-256"],
                         [[text(f.get("role", "")), Cell(esc(f.get("path", "")), "text-small"),
                           num(rd.number(f.get("bytes")), ".0f"), Cell(esc(f.get("sha256", "")), "hash")]
                          for f in inputs]))
    else:
        out.append(note("Input files: not listed in this result (written by an older aerocal)."))
    return "".join(out)


def problems(doc):
    """(invalid, warnings): the reasons the result is not valid, and the warnings, as sentences."""
    invalid, warnings = [], []
    for f in rd.listing(doc.get("failures")):
        if isinstance(f, dict):
            invalid.append(f"{f.get('step', '?')}: {f.get('reason', '')}")
    for a in rd.adjustments(doc):
        t = rd.title(a)
        if a.get("converged") is False:
            invalid.append(f"{t}: did not converge")
        invalid += [f"{t}: {r}" for r in map(str, rd.listing(a.get("invalid_reasons")))
                    if f"{t}: {r}" not in invalid and not any(r in i for i in invalid)]
        warnings += [f"{t}: {w.get('message') if isinstance(w, dict) else w}" for w in rd.listing(a.get("warnings"))]
        snooping = a.get("snooping") if isinstance(a.get("snooping"), dict) else {}
        if snooping.get("model_error_suspected"):
            evidence = "; ".join(map(str, rd.listing(snooping.get("model_error_evidence"))))
            warnings.append(f"{t}: model error suspected ({evidence})")
    return invalid, warnings


def verdict(doc):
    """One line, consistent with the warnings: never "valid" in green above a red warning."""
    invalid, warnings = problems(doc)
    if invalid or doc.get("valid") is False:
        return ('<p class="verdict bad" id="verdict">Verdict: NOT VALID: ' + esc(invalid[0] if invalid else
                "the result is marked not valid") + (f" (and {len(invalid) - 1} more reason(s), below)"
                                                     if len(invalid) > 1 else "") + ".</p>")
    if warnings:
        return (f'<p class="verdict warn" id="verdict">Verdict: converged, with {len(warnings)} warning(s) to '
                f"resolve before the result is used: {esc(warnings[0])}.</p>")
    return '<p class="verdict ok" id="verdict">Verdict: valid: every step converged, no warning.</p>'


def advice(doc):
    """Advice that depends on the case; an empty list when there is nothing to do."""
    out = []
    main = _main_adjustment(doc)
    if not main:
        return out
    geo = geometry(doc, main)
    aerial = bool(geo and geo["aerial"])
    exposures = [e for e in rd.listing(main.get("exposures")) if isinstance(e, dict)]
    # GNSS/IMU priors are the residual group eo_prior (calib/problem/problem_builder.h).
    gnss = any(isinstance(g, dict) and g.get("name") == "eo_prior" for g in rd.listing(main.get("groups")))
    snooping = main.get("snooping") if isinstance(main.get("snooping"), dict) else {}
    if snooping.get("model_error_suspected") and snooping.get("suggestion"):
        out.append(f"Model error suspected: {snooping.get('suggestion')}.")
    rejected = [r for r in rd.listing(main.get("rejected")) if isinstance(r, dict)]
    if rejected:
        out.append(f"Re-measure or remove the {len(rejected)} rejected observation(s) (listed with their w) and run "
                   "again: the result holds without them, but the measurements should be corrected at the source.")
    weak = [u for u in rd.listing(snooping.get("uncontrolled")) if isinstance(u, dict)]
    two_ray = sorted({str(u.get("point")) for u in weak if rd.number(u.get("rays")) == 2})
    if two_ray:
        out.append(f"Points seen in two images only ({', '.join(two_ray[:10])}): a blunder along the base is "
                   "invisible there; measure them in a third image.")
    left = [e for e in exposures if e.get("used") is False]
    if left:
        out.append(f"Images left out ({', '.join(str(e.get('image')) for e in left)}): measure at least three "
                   "points in each to include them.")
    check = rd.point_statistics(main, "check")
    if check and check["n"] is not None and check["n"] < 20 and aerial:
        out.append(f"Only {int(check['n'])} check points: an accuracy statement per ASPRS (2014) needs at least 20.")
    if check and (check["n"] or 0) == 0:
        out.append("No check points: the accuracy of the block is not proven independently; keep some surveyed "
                   "points as check points.")
    held = [h for h in rd.listing(rd.get(main.get("self_calibration_choice"), "held")) if isinstance(h, dict)
            and "not determinable" in str(h.get("reason", ""))]
    if held:
        names = ", ".join(str(h.get("parameter")) for h in held)
        how = ("fly a second height or cross strips, and use GNSS-supported projection centres" if aerial and not gnss
               else "fly a second height or cross strips" if aerial else
               "add convergent and rolled (90 deg kappa) images at several distances")
        out.append(f"Not determinable in this block and held at the camera file's values: {names}; to calibrate "
                   f"them, {how}.")
    return out
