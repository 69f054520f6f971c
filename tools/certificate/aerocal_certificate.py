#!/usr/bin/env python3
"""Renders the calibration certificate of `aerocal certificate`.

Usage: aerocal_certificate.py CERTIFICATE.json OUT_DIR
Writes OUT_DIR/certificate.html (figures inline as SVG) and OUT_DIR/certificate.pdf: the same page
typeset for A4 by weasyprint (Debian's `weasyprint`, installed by tools/setup.sh, as for the flight
report): tables, figures and the model as on the page, the title and "page x of y" on every page.
Without weasyprint the PDF is drawn with matplotlib's PDF backend instead (monospace tables and the
figures; a note on stderr says so). Both outputs are deterministic: no dates other than the lab
file's, fixed SVG ids, no creation date in the PDF. Exit 0 on success, 2 on bad input (nothing
written), 1 when matplotlib is missing.
"""
import base64
import html
import io
import json
import math
import os
import sys
import textwrap

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages
    import numpy as np
except ImportError as e:  # pragma: no cover
    print("error: matplotlib/numpy missing: %s" % e, file=sys.stderr)
    sys.exit(1)

matplotlib.rcParams["svg.hashsalt"] = "aerocal-certificate"
matplotlib.rcParams["font.size"] = 8
# Every text drawn is the user's or ours, never mathtext: a `$...$` in a lab field crashed the
# renderer (issue 37). matplotlib >= 3.6 has the switch; older ones get every `$` escaped (plain()).
try:
    matplotlib.rcParams["text.parse_math"] = False
    MATH_OFF = True
except KeyError:  # pragma: no cover
    MATH_OFF = False
A4 = (8.27, 11.69)


def fmt(v, digits=6):
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int,)):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "-"
        return "%.*g" % (digits, v)
    return str(v)


def fmt_u(v):
    """An expanded uncertainty with two significant digits, trailing zeros kept (0.60, 1.0e-06)."""
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v <= 0:
        return "-"
    text = "%#.2g" % v
    return text[:-1] if text.endswith(".") else text


def unit_of(unit):
    """A table unit for people: the dimensionless "1" is written as "-" (never `unit 1`)."""
    return "-" if unit in ("1", "", None) else unit


def is_draft(c):
    """No laboratory file: no lab name and no certificate number. Such a document is a draft and
    is not called a certificate (ISO/IEC 17025 7.8.2: a certificate names the laboratory)."""
    lab = c.get("lab") or {}
    return not (lab.get("lab") or {}).get("name") and not (lab.get("certificate") or {}).get("number")


def title_of(c):
    if is_draft(c):
        return "DRAFT calibration report (no laboratory file: not a certificate)"
    return "Calibration certificate %s" % c["lab"]["certificate"]["number"]


# ---------------------------------------------------------------- tables (lists of rows)

def result_rows(c):
    rows = [["quantity", "value", "U", "k", "unit", "nu_eff"]]
    for q in c["results"]:
        rows.append([q["quantity"], fmt(q["value"], 7), fmt_u(q["U"]), fmt(q["k"], 3), unit_of(q["unit"]),
                     fmt(q["dof_eff"], 3)])
    return rows


def budget_rows(results):
    """One budget table: every quantity's components and its combined / expanded uncertainty."""
    rows = [["quantity", "component", "type", "distribution", "u_i", "nu_i"]]
    for q in results:
        for comp in q["components"]:
            rows.append([q["quantity"], comp["source"], comp["type"], comp["distribution"],
                         fmt(comp["u"], 3), fmt(comp["dof"], 3)])
        rows.append([q["quantity"], "combined u_c / expanded U", "", "k = %s" % fmt(q["k"], 3),
                     fmt(q["u_c"], 3) + " / " + fmt_u(q["U"]), fmt(q["dof_eff"], 3)])
    return rows


def budget_tables(c):
    """[(heading, rows)]: a rig's heads (certificate.json `heads`) one budget table each, from the
    head's own rows as aerocal computed them, then the rows of no head (m_0: one adjustment); a
    single camera one table of all its rows."""
    heads = c.get("heads") or []
    if not heads:
        return [("", budget_rows(c["results"]))]
    out = [("head %s (radii %s mm)" % (h.get("id", "?"), ", ".join(fmt(r, 4) for r in h.get("radii_mm") or [])),
            budget_rows(h.get("results") or [])) for h in heads]
    of_heads = {q["quantity"] for h in heads for q in h.get("results") or []}
    rest = [q for q in c["results"] if q["quantity"] not in of_heads]
    if rest:
        out.append(("the adjustment of all heads", budget_rows(rest)))
    return out


def source_rows(c):
    """Where each component comes from (ISO/IEC 17025 7.8.4 / GUM 7.2.7: every source named), once per
    kind of component; a component without an `origin` (an older result) says so."""
    rows = [["component", "type", "quantities", "where it comes from"]]
    seen = {}
    for q in c["results"]:
        for comp in q["components"]:
            key = (comp["source"], comp["type"], comp.get("origin") or "not stated (older result)")
            seen.setdefault(key, []).append(q["quantity"])
    for (source, kind, origin), quantities in seen.items():
        names = ", ".join(quantities) if len(quantities) <= 6 else "%s, ... (%d)" % (
            ", ".join(quantities[:5]), len(quantities))
        rows.append([source, kind, names, origin])
    return rows


def stability_rows(c):
    s = c.get("stability") or {}
    groups = c.get("groups") or []
    if not groups:
        return None
    # The change of one group alone the test flags with probability `power` (per group).
    power = s.get("power")
    detect = "detectable change (%s)" % ("%.0f %%" % (100 * power) if power else "-")
    head = ["parameter"] + [g["group"] for g in groups] + ["mean", "spread", "chi2", "critical", detect, "agree"]
    rows = [head]
    for r in s.get("rows", []):
        d = r.get("detectable_change")
        rows.append([r["parameter"]] + [fmt(v, 7) + " +- " + fmt(sg, 2) for v, sg in zip(r["values"], r["sigmas"])] +
                    [fmt(r["mean"], 7), fmt(r["spread"], 2), fmt(r["chi2"], 3), fmt(r["critical"], 3),
                     " / ".join(fmt(x, 2) for x in d) if d else "-",
                     "yes" if r["agree"] else "NO"])
    return rows


def check_rows(c):
    chk = c.get("check") or {}
    n = chk.get("n", 0)
    rows = [["quantity", "value", "U (k)", "unit"]]
    by_name = {q["quantity"]: q for q in c["results"]}
    for name in ["m_X", "m_Y", "m_Z", "m_0"]:
        q = by_name.get(name)
        if q:
            rows.append([name, fmt(q["value"], 4), "%s (%s)" % (fmt_u(q["U"]), fmt(q["k"], 3)), unit_of(q["unit"])])
    rows.append(["check points n", str(n), "", ""])
    if n:
        rows.append(["mean X / Y / Z", " / ".join(fmt(1e3 * v, 3) for v in chk["mean_m"]), "", "mm"])
        rows.append(["max |d| X / Y / Z", " / ".join(fmt(1e3 * v, 3) for v in chk["max_abs_m"]), "", "mm"])
    return rows


def comparison_rows(c):
    cmp = c.get("comparison")
    if not cmp:
        return None
    rows = [["quantity", "now", "previous", "difference", "tolerance", "E_n", "criterion", "result"]]
    for r in cmp["rows"]:
        judged = r.get("judged", True)
        verdict = ("pass" if r["pass"] else "FAIL") if judged else \
            "not judged (%s)" % ("consistent" if r["pass"] else "differs")
        rows.append([r["quantity"], fmt(r["value"], 7), fmt(r["previous"], 7), fmt(r["difference"], 3),
                     fmt(r["tolerance"], 3), fmt(r["E_n"], 3), r["criterion"], verdict])
    return rows


COMPARISON_NOTE = ("The comparison judges the camera: its parameters and distortion values. sigma0 (m_0) "
                   "and the check-point RMSEs (m_X, m_Y, m_Z) are properties of the run (images, targets, "
                   "pointing), listed for information and not counted in the overall result.")


def identification_rows(c):
    lab, cam, cf = c["lab"], c["lab"]["camera"], c["camera_file"]
    m, d, a = c["method"], c["data"], c["adjustment"]
    rows = [["field", "value"]]
    if not is_draft(c):
        rows += [["certificate number", lab["certificate"]["number"]],
                 ["date", lab["certificate"]["date"]],
                 ["laboratory", lab["lab"]["name"]],
                 ["address", lab["lab"]["address"]],
                 ["accreditation", lab["lab"]["accreditation"]],
                 ["customer", lab["customer"]["name"]]]
    camera = " ".join(x for x in (cam["make"], cam["model"]) if x) or c.get("interior", {}).get("id") or "-"
    rows += [["camera", camera + (", serial %s" % cam["serial"] if cam["serial"] else ", serial not given")],
             ["lens", " ".join(x for x in (cam["lens"], cam["lens_serial"]) if x) or "-"],
            ["camera file", "%s: pixel %s mm, format %s x %s px" % (cf["file"], fmt(cf["pixel_size_mm"]),
                                                                   cf["format_px"][0], cf["format_px"][1])],
            ["method", method_text(m)],
            ["data", data_text(m, d)],
            ["adjustment", adjustment_kind(m) + " (%s); sigma0 %s (%s px, %s um), redundancy %s, RMS %s px" % (
                ", ".join(a.get("self_calibration") or []) if isinstance(a.get("self_calibration"), list) else fmt(a.get("self_calibration")),
                fmt(a["sigma0"], 4), fmt(a["sigma0_px"], 4), fmt(a["sigma0_um"], 4), fmt(a["redundancy"]), fmt(a["rms_px"], 4))],
            ["conditions", ", ".join("%s %s" % (k, v) for k, v in lab["conditions"].items() if v) or "-"],
            ["valid", validity(c)]]
    if c.get("opencv"):
        o = c["opencv"]
        rows.append(["peer: cv::calibrateCamera", "RMS %s px, fx %s, fy %s, cx %s, cy %s px (c %s, x0 %s, y0 %s mm)" % (
            fmt(o["rms_px"], 5), fmt(o["fx"], 7), fmt(o["fy"], 7), fmt(o["cx"], 7), fmt(o["cy"], 7),
            fmt(o["equivalent"]["c"], 6), fmt(o["equivalent"]["x0"], 4), fmt(o["equivalent"]["y0"], 4))])
    return rows


def validity(c):
    """"yes" only when the adjustment is valid AND every test passed: group stability and the
    comparison with a previous certificate (a failed test is never "valid yes")."""
    reasons = list(c["adjustment"].get("invalid_reasons") or []) if not c["adjustment"]["valid"] else []
    stability = c.get("stability") or {}
    if c.get("groups") and stability.get("agree") is False:
        disagree = [r["parameter"] for r in stability.get("rows", []) if not r.get("agree")]
        reasons.append("the image groups disagree (%s)" % ", ".join(disagree))
    if c.get("comparison") and not c["comparison"].get("pass"):
        reasons.append("the camera differs from the previous certificate")
    return "yes" if not reasons else "NO: " + "; ".join(reasons)


def model_rows(c):
    """The camera model written out: which parameters were estimated and which held."""
    interior = c.get("interior") or {}
    free = set(interior.get("free") or [])
    rows = [["parameter", "unit", "meaning", "this calibration"]]
    meaning = {"c": "principal distance", "x0": "principal point x (photo frame, from the format centre)",
               "y0": "principal point y (photo frame, y up)", "K1": "radial", "K2": "radial", "K3": "radial",
               "P1": "decentring", "P2": "decentring", "B1": "affinity (scale of x)", "B2": "shear"}
    for p in (c.get("camera_model") or {}).get("parameters", []):
        held = interior.get("estimated", {}).get(p["name"])
        rows.append([p["name"], unit_of(p["unit"]), meaning.get(p["name"], p.get("group", "").replace("_", " ")),
                     "estimated" if p["name"] in free else "held at %s" % fmt(held)])
    return rows


MODEL_TEXT_BROWN_FRASER = (
    "Photo frame: origin at the centre of the image format, x to the right, y up, in mm; pixel (col, row) "
    "-> x = (col - (W - 1)/2) p, y = -(row - (H - 1)/2) p, p the pixel size. The principal point (x0, y0) "
    "is the foot of the perpendicular from the projection centre, in that frame (positive x0: right of "
    "the format centre; positive y0: above it). Correction form (Brown / Fraser 1997), evaluated at the "
    "measured (x, y): with xb = x - x0, yb = y - y0, r^2 = xb^2 + yb^2, "
    "dx = xb (K1 r^2 + K2 r^4 + K3 r^6) + P1 (r^2 + 2 xb^2) + 2 P2 xb yb + B1 xb + B2 yb, "
    "dy = yb (K1 r^2 + K2 r^4 + K3 r^6) + 2 P1 xb yb + P2 (r^2 + 2 yb^2); the ideal point is "
    "(xb + dx, yb + dy) = -c (U, V) / W (collinearity). dr@R is the radial correction "
    "R (K1 R^2 + K2 R^4 + K3 R^6) at the radius R mm from the principal point, dt@R the magnitude of the "
    "decentring correction sqrt(P1^2 + P2^2) R^2 there, both in um.")


def model_text(c):
    name = (c.get("camera_model") or {}).get("name", "brown_fraser_10")
    if name == "brown_fraser_10":
        return MODEL_TEXT_BROWN_FRASER
    return ("Camera model %s in the photo frame of aerocal (origin at the format centre, x right, y up, mm); "
            "its parameters and equations: docs/conventions.md section 3 of aerocal." % name)


def resolution_edge_rows(c):
    """Section 9 (dynamic image resolution): one row per slanted edge (`aerocal quality mtf`)."""
    d = c.get("dynamic_image_resolution") or {}
    rows = [["edge", "roi col,row,w,h", "axis", "direction", "slant deg", "MTF50 cy/px", "U", "lp/mm", "U",
             "GRD m", "U", "MTF Nyquist"]]
    for i, e in enumerate(d.get("edges", [])):
        rows.append([i + 1, ",".join(str(v) for v in e.get("roi", [])), e.get("axis", "-"), e.get("direction", "-"),
                     fmt(e.get("angle_deg"), 3), fmt(e.get("mtf50_cy_px"), 4), fmt(e.get("mtf50_expanded_cy_px"), 2),
                     fmt(e.get("mtf50_lp_per_mm"), 4), fmt(e.get("mtf50_lp_per_mm_expanded"), 2),
                     fmt(e.get("mtf50_resolved_distance_m"), 4), fmt(e.get("mtf50_resolved_distance_expanded_m"), 2),
                     fmt(e.get("mtf_nyquist"), 3)])
    return rows if len(rows) > 1 else []


def resolution_axis_rows(c):
    """Repeated edges of one axis combined: type A from their scatter, type B the systematic part."""
    d = c.get("dynamic_image_resolution") or {}
    # One row per quality result and axis: the result's file name says which image (a sub-image, a
    # head or the virtual image) its edges were measured in.
    rows = [["result", "axis", "direction", "edges", "MTF50 cy/px", "u_A", "u_B", "U (k=2)", "lp/mm", "U",
             "GRD m", "U"]]
    for a in d.get("axes", []):
        source = os.path.splitext(os.path.basename(a.get("source", "-")))[0]
        rows.append([source, a.get("axis"), a.get("direction", "-"), a.get("count"), fmt(a.get("mtf50_cy_px"), 4),
                     fmt(a.get("type_a_u_cy_px"), 2), fmt(a.get("type_b_u_cy_px"), 2),
                     fmt(a.get("mtf50_expanded_cy_px"), 2), fmt(a.get("mtf50_lp_per_mm"), 4),
                     fmt(a.get("mtf50_lp_per_mm_expanded"), 2), fmt(a.get("mtf50_resolved_distance_m"), 4),
                     fmt(a.get("mtf50_resolved_distance_expanded_m"), 2)])
    return rows if len(rows) > 1 else []


def resolution_loss_rows(c):
    """The resampling loss per axis: the virtual image's MTF50 against the raw sub-images' mean
    (computed by tools/dynamic_resolution.cc from results named `--sub-image` / `--virtual`)."""
    d = c.get("dynamic_image_resolution") or {}
    rows = [["resampling loss", "direction", "raw sub-images", "raw mean cy/px", "virtual cy/px", "loss cy/px",
             "U", "loss %", "U %"]]
    for r in d.get("resampling_loss", []):
        rows.append([r.get("axis"), r.get("direction") or "-", ", ".join(r.get("sub_images", [])),
                     fmt(r.get("raw_mean_mtf50_cy_px"), 4), fmt(r.get("virtual_mtf50_cy_px"), 4),
                     fmt(r.get("loss_cy_px"), 4), fmt(r.get("loss_expanded_cy_px"), 2),
                     fmt(r.get("loss_percent"), 3), fmt(r.get("loss_expanded_percent"), 2)])
    return rows if len(rows) > 1 else []


def resolution_bar_rows(c):
    """Bar targets (`aerocal quality bars`): the limiting frequency at the threshold."""
    d = c.get("dynamic_image_resolution") or {}
    rows = [["bar target", "threshold", "groups", "limiting cy/px", "lp/mm", "GRD m", "within the target"]]
    for i, b in enumerate(d.get("bars", [])):
        rows.append([i + 1, fmt((b.get("options") or {}).get("threshold"), 3), len(b.get("groups", [])),
                     fmt(b.get("limiting_frequency_cy_px"), 4), fmt(b.get("limiting_lp_per_mm"), 4),
                     fmt(b.get("limiting_resolved_distance_m"), 4), fmt(b.get("limit_in_range"))])
    return rows if len(rows) > 1 else []


def resolution_star_rows(c):
    """Siemens stars (`aerocal quality star`): the limiting frequency at the threshold."""
    d = c.get("dynamic_image_resolution") or {}
    rows = [["Siemens star", "cycles", "threshold", "limiting cy/px", "radius px", "lp/mm", "GRD m",
             "within the star"]]
    for i, s in enumerate(d.get("stars", [])):
        rows.append([i + 1, (s.get("star") or {}).get("cycles", "-"), fmt((s.get("options") or {}).get("threshold"), 3),
                     fmt(s.get("limiting_frequency_cy_px"), 4), fmt(s.get("limiting_radius_px"), 4),
                     fmt(s.get("limiting_lp_per_mm"), 4), fmt(s.get("limiting_resolved_distance_m"), 4),
                     fmt(s.get("limit_in_range"))])
    return rows if len(rows) > 1 else []


def fig_mtf(c):
    """MTF curves of the edges, contrast transfer of the bar groups and of the stars' rings, cycles/px."""
    d = c.get("dynamic_image_resolution") or {}
    fig, ax = plt.subplots(figsize=(7.0, 3.6))
    for i, e in enumerate(d.get("edges", [])):
        curve = e.get("curve") or {}
        f, m = curve.get("frequency_cy_px", []), curve.get("mtf", [])
        pts = [(x, y) for x, y in zip(f, m) if x is not None and y is not None and x <= 0.75]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "-",
                    label="edge %d (%s)" % (i + 1, e.get("direction", e.get("axis", ""))))
    for i, b in enumerate(d.get("bars", [])):
        g = b.get("groups", [])
        ax.plot([x["frequency_cy_px"] for x in g], [x["contrast_transfer"] for x in g], "o--",
                label="bar target %d (contrast transfer)" % (i + 1))
    for i, s in enumerate(d.get("stars", [])):
        r = s.get("rings", [])
        ax.plot([x["frequency_cy_px"] for x in r], [x["contrast_transfer"] for x in r], ".:",
                label="Siemens star %d (modulation transfer)" % (i + 1))
    ax.axhline(0.5, color="#999", lw=0.6)
    ax.axvline(0.5, color="#999", lw=0.6, ls=":")
    ax.set_xlabel("frequency (cycles/px); Nyquist 0.5")
    ax.set_ylabel("MTF / contrast transfer")
    ax.set_xlim(0, 0.75)
    ax.set_ylim(0, 1.05)
    if ax.lines:
        ax.legend(fontsize=6)
    fig.tight_layout()
    return fig


def data_text(m, d):
    """The data row: images and points, or for a direction calibration targets and settings."""
    if m.get("kind") in ("collimator array", "goniometer"):
        return "%d observations of %d targets (%d of known direction), %d settings, %d groups" % (
            d["observations"], d.get("targets", 0), d["control_points"], d.get("settings", 0), d["groups"])
    return "%d images, %d observations, %d control, %d check points, %d groups" % (
        d["images"], d["observations"], d["control_points"], d["check_points"], d["groups"])


def adjustment_kind(m):
    """The adjustment the method ran: directions (no positions) or a bundle adjustment."""
    if m.get("kind") in ("collimator array", "goniometer"):
        return "direction adjustment"
    return "self-calibrating bundle adjustment"


def method_text(m):
    if m.get("kind") == "in-flight calibration":
        return "in-flight calibration (aerocal flight, %s adjustment) of %s; uncertainty budget: %s" % (
            m.get("adjustment"), m.get("flight_data"), m.get("budget"))
    if m.get("kind") in ("collimator array", "goniometer"):
        units = ""
        if m.get("units"):
            units = "; units %s in one adjustment (each unit's values with U: rows UNIT.quantity)" % (
                ", ".join(m["units"]))
        return "%s (laboratory, known directions): %s; %d targets (%d of known direction), %d settings; %s%s" % (
            m["kind"], m.get("directions"), m.get("targets", 0), m.get("known_targets", 0), m.get("settings", 0),
            m.get("adjustment", ""), units)
    if m.get("kind") == "planar target":
        return "planar %s %dx%d, spacing %s mm, %s; %d of %d images detected" % (
            m["board"], m["columns"], m["rows"], fmt(m["spacing_mm"]), m["detector"], len(m["detected"]),
            len(m["detected"]) + len(m["not_detected"]))
    return "test field: %s, %s; starting orientation by resection (aerocal)" % (m.get("observations"), m.get("points"))


def warning_lines(c):
    """Every finding once: the adjustment's warnings, then the flagged groups unless a warning of
    the adjustment already states the group test."""
    out = []
    for w in c["adjustment"].get("warnings") or []:
        line = "%s: %s" % (w.get("name"), w.get("message"))
        if line not in out:
            out.append(line)
    stated = any(w.get("name") == "group_stability" for w in c["adjustment"].get("warnings") or [])
    for f in (c.get("stability") or {}).get("flagged", []):
        line = "group stability: " + f
        if not stated and line not in out:
            out.append(line)
    return out


def type_a_note(c):
    """What is type A only and which type B components were found empty, said in the document (not
    only in the JSON)."""
    kinds = {comp["type"] for q in c["results"] for comp in q["components"]
             if comp.get("u") and comp["u"] > 0}
    if kinds == {"A"}:
        return ("This budget holds type A components only (the adjustment's statistics): no type B "
                "component is known for this calibration (give a budget file: aerocal calibrate --budget).")
    type_a = sorted({comp["source"] for q in c["results"] for comp in q["components"] if comp["type"] == "A"})
    zero_b = sorted({"%s (%s)" % (comp["source"], comp["origin"]) if comp.get("origin") else comp["source"]
                     for q in c["results"] for comp in q["components"]
                     if comp["type"] == "B" and not comp.get("u") and not is_independent(comp)})
    note = ("Type A (statistical, from this calibration's data): %s; every other component is type B "
            "(the table below says where each comes from)." % ", ".join(type_a)) if type_a else ""
    if zero_b:
        note += " Type B components of zero size (their source gave no uncertainty): %s." % "; ".join(zero_b)
    return note.strip()


def is_independent(comp):
    """A type B component the quantity does not depend on (sensitivity 0: a quantity in pixels and the
    pixel pitch) is no missing source."""
    return comp.get("sensitivity") == 0 and comp.get("value")


# ---------------------------------------------------------------- figures

def unit_panels(c):
    """[(title prefix, quantity prefix, distortion, correlation)]: one per rig head when the certificate
    has `heads` (every head's samples, computed by aerocal: tools/certificate_writer.cc HeadsJson),
    else the certificate's own single camera."""
    units = c.get("heads") or []
    if units:
        return [("head %s: " % u.get("id", "?"), "%s." % u.get("id", "?"), u.get("distortion"),
                 u.get("correlation")) for u in units]
    return [("", "", c.get("distortion"), c.get("correlation"))]


def certified_points(c, prefix):
    """[(radius, value, U, key)] of the budget rows "PREFIXdr@R" / "PREFIXdt@R" that have a U."""
    out = []
    for q in c["results"]:
        name = q["quantity"]
        if not name.startswith(prefix) or q.get("U") is None:
            continue
        rest = name[len(prefix):]
        for key in ("dr", "dt"):
            if rest.startswith(key + "@"):
                try:
                    out.append((float(rest[len(key) + 1:]), q["value"], q["U"], key))
                except ValueError:
                    pass
    return out


def draw_distortion(ax1, ax2, d, c, title, prefix):
    """One camera's distortion curves and correction grid from aerocal's samples `d`."""
    if not d:
        for ax in (ax1, ax2):
            ax.axis("off")
        ax1.text(0, 0.5, "%sno distortion samples in certificate.json" % title, fontsize=9)
        return
    r, dr, dt = zip(*d["profile"])
    terms = d["profile_kind"] == "10-parameter terms"
    ax1.plot(r, dr, label="radial dr(r)" if terms else "radial dr(r), mean over directions")
    ax1.plot(r, dt, label="decentring |dt|(r)" if terms else "tangential, RMS over directions")
    for rad, value, u, key in certified_points(c, prefix):
        ax1.errorbar([rad], [value], yerr=[u], fmt="o", color="C0" if key == "dr" else "C1", capsize=3, ms=3)
    ax1.set_xlabel("radius r (mm)")
    ax1.set_ylabel("distortion (um)")
    ax1.set_title("%sdistortion curves (bars: U, k as stated)" % title)
    ax1.grid(True, lw=0.3)
    ax1.legend()
    # Distortion grid over the format (photo frame, mm; vectors exaggerated).
    gx, gy, dx, dy = zip(*d["grid"]) if d["grid"] else ([], [], [], [])
    q = ax2.quiver(gx, gy, dx, dy, angles="xy")
    longest = max([1e-9] + [math.hypot(a, b) for a, b in zip(dx, dy)])
    ax2.quiverkey(q, 0.8, 1.04, longest, "%.3g um" % longest, labelpos="E")
    ax2.set_aspect("equal")
    ax2.set_xlabel("x (mm)")
    ax2.set_ylabel("y (mm)")
    ax2.set_title("%scorrection dx, dy over the format" % title, pad=14)


def fig_distortion(c):
    """The camera's correction as aerocal computed it in its model (certificate.json `distortion`:
    triangulation/calibration/distortion_figure.h; a rig's heads: one row per head from
    `heads`); this script restates no camera model."""
    panels = unit_panels(c)
    fig, axes = plt.subplots(len(panels), 2, figsize=(8, 3.4 * len(panels)), squeeze=False)
    for (title, prefix, d, _), (ax1, ax2) in zip(panels, axes):
        draw_distortion(ax1, ax2, d, c, title, prefix)
    fig.tight_layout()
    return fig


def draw_correlation(ax, corr, title):
    """The interior parameters' correlation matrix as aerocal exported it."""
    if corr and corr.get("correlation"):
        m = np.array(corr["correlation"])
        im = ax.imshow(m, vmin=-1, vmax=1, cmap="RdBu_r")
        names = corr["names"]
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names, rotation=90)
        ax.set_yticks(range(len(names)))
        ax.set_yticklabels(names)
        for i in range(len(names)):
            for j in range(len(names)):
                ax.text(j, i, "%.2f" % m[i, j], ha="center", va="center", fontsize=5)
        ax.figure.colorbar(im, ax=ax, shrink=0.8)
    ax.set_title("%scorrelation of the interior parameters" % title)


def fig_residuals_correlation(c):
    """The residual vectors of all images, then one correlation map per head (a single camera: one),
    two panels a row."""
    panels = unit_panels(c)
    rows = (len(panels) + 2) // 2
    fig, axes = plt.subplots(rows, 2, figsize=(8, 3.6 * rows), squeeze=False)
    axes = list(axes.flat)
    ax1 = axes[0]
    cf = c["camera_file"]
    w, h = cf["format_px"]
    res = c.get("residuals") or []
    if res:
        a = np.array(res, dtype=float)
        q = ax1.quiver(a[:, 0], a[:, 1], a[:, 2], -a[:, 3], angles="xy", scale_units="xy",
                       scale=1.0 / (0.08 * w / max(1e-9, np.percentile(np.hypot(a[:, 2], a[:, 3]), 99))))
        ax1.quiverkey(q, 0.8, 1.04, 1.0, "1 px", labelpos="E")
    ax1.set_xlim(0, w)
    ax1.set_ylim(h, 0)
    ax1.set_aspect("equal")
    ax1.set_title("image residuals (all images)", pad=14)
    ax1.set_xlabel("col (px)")
    ax1.set_ylabel("row (px)")
    for (title, _, _, corr), ax in zip(panels, axes[1:]):
        draw_correlation(ax, corr, title)
    for ax in axes[1 + len(panels):]:
        ax.axis("off")
    fig.tight_layout()
    return fig


def svg_of(fig):
    """The figure as an SVG image in the HTML (a data URI, not inline markup): WeasyPrint 57 does not
    draw the <use> references of matplotlib's glyph paths in an inline SVG, which left the PDF's
    figures without any label, tick or legend text."""
    buf = io.StringIO()
    fig.savefig(buf, format="svg", metadata={"Date": None})
    plt.close(fig)
    text = buf.getvalue()
    svg = text[text.index("<svg"):]
    data = base64.b64encode(svg.encode("utf-8")).decode("ascii")
    return f'<img class="figure" alt="figure" src="data:image/svg+xml;base64,{data}">'


# ---------------------------------------------------------------- HTML

def html_table(rows, flag_col=None):
    out = ["<table><tr>" + "".join("<th>%s</th>" % html.escape(str(x)) for x in rows[0]) + "</tr>"]
    for r in rows[1:]:
        cls = ""
        if flag_col is not None and str(r[flag_col]) in ("NO", "FAIL"):
            cls = ' class="bad"'
        out.append("<tr%s>" % cls + "".join("<td>%s</td>" % html.escape(str(x)) for x in r) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def page_html(c, figures):
    """The certificate as one HTML page (print rules for A4 included)."""
    lab = c["lab"]
    draft = is_draft(c)
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>%s</title>" % html.escape(title_of(c)),
             "<style>body{font-family:sans-serif;max-width:60em;margin:auto;font-size:11pt}"
             "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #999;padding:2px 6px;"
             "text-align:left;font-size:10pt}.bad{color:#b00;font-weight:bold}.sig td{height:3em;width:14em}"
             ".draft{color:#b00;border:2px solid #b00;padding:4px 8px;font-weight:bold}"
             "h1{font-size:18pt}h2{font-size:13pt;border-bottom:1px solid #999}img.figure{max-width:100%;height:auto}"
             "@page{size:A4;margin:18mm 14mm 16mm;@top-left{content:string(title);font-family:sans-serif;font-size:8pt;color:#555}"
             "@bottom-right{content:'page ' counter(page) ' of ' counter(pages);font-family:sans-serif;font-size:8pt}}"
             "h1{string-set:title content()}"
             "@media print{body{max-width:none;font-size:9pt}td,th{font-size:7.5pt}"
             "h2{break-after:avoid}}</style></head><body>",
             "<h1>%s</h1>" % html.escape(title_of(c))]
    if draft:
        parts.append("<p class='draft'>DRAFT: no laboratory file (--lab) was given. This document states "
                     "aerocal's results and their budget; it is not a calibration certificate (ISO/IEC 17025 "
                     "7.8: a certificate names the laboratory, its number and date, and is signed).</p>")
    else:
        parts.append("<p>%s<br>%s<br>%s</p>" % tuple(html.escape(lab["lab"][k])
                                                   for k in ("name", "address", "accreditation")))
    parts += ["<h2>1. Identification, method and data</h2>", html_table(identification_rows(c)),
              "<h3>Camera model</h3><p>%s</p>" % html.escape(model_text(c)), html_table(model_rows(c)),
              "<h2>2. Results</h2><p>Each value with its expanded uncertainty U = k u_c (ISO GUM / JJF 1059.1), "
              "coverage probability about 95 %; U with two significant digits.</p>",
              "<ul>" + "".join("<li>%s</li>" % html.escape(q["statement"]) for q in c["results"]) + "</ul>",
              html_table(result_rows(c)),
              "<h2>3. Uncertainty budget</h2>", "<p>%s</p>" % html.escape(type_a_note(c))]
    for heading, rows in budget_tables(c):
        parts += (["<h3>Budget of %s</h3>" % html.escape(heading)] if heading else []) + [html_table(rows)]
    parts += ["<h3>Sources of the components</h3>", html_table(source_rows(c)),
              "<h2>4. Distortion</h2>", figures["distortion"],
              "<h2>5. Residuals and correlations</h2>", figures["residuals"]]
    st = stability_rows(c)
    parts.append("<h2>6. Stability over image groups</h2>")
    parts.append(html_table(st, flag_col=len(st[0]) - 1) if st else "<p>No image groups given.</p>")
    parts += ["<h2>7. Check points</h2>", html_table(check_rows(c))]
    cmp = comparison_rows(c)
    parts.append("<h2>8. Comparison with the previous certificate</h2>")
    if cmp:
        parts.append("<p>Previous: %s. Overall (the camera's parameters): <b>%s</b>. %s</p>" % (
            html.escape(c["comparison"]["previous"]), "pass" if c["comparison"]["pass"] else "FAIL",
            html.escape(COMPARISON_NOTE)))
        parts.append(html_table(cmp, flag_col=7))
    else:
        parts.append("<p>No previous certificate given.</p>")
    if c.get("dynamic_image_resolution"):
        d = c["dynamic_image_resolution"]
        parts.append("<h2>9. Dynamic image resolution</h2><p>%s; MTF50 with U = k u_c (k = 2); GRD = GSD / "
                     "(2 f), one bar width. Sources: %s.</p>" % (
                         html.escape(d.get("method", "bar targets")), html.escape(", ".join(d.get("sources", [])))))
        for rows in (resolution_edge_rows(c), resolution_axis_rows(c), resolution_loss_rows(c),
                     resolution_bar_rows(c), resolution_star_rows(c)):
            if rows:
                parts.append(html_table(rows))
        parts.append(figures["mtf"])
    warnings = warning_lines(c)
    if warnings:
        parts.append("<h2>Findings</h2><ul>" + "".join("<li class='bad'>%s</li>" % html.escape(w) for w in warnings) + "</ul>")
    s = lab["signatures"]
    if not draft:
        parts.append("<h2>Signatures</h2><table class='sig'><tr><th>calibrated by</th><th>checked by</th>"
                     "<th>approved by</th></tr><tr><td>%s</td><td>%s</td><td>%s</td></tr></table>"
                     % tuple(html.escape(s[k]) for k in ("calibrated_by", "checked_by", "approved_by")))
    parts.append("<p>%s</p></body></html>" % html.escape(lab["certificate"]["page_note"]))
    return "\n".join(parts) + "\n"


def write_atomically(path, data):
    """`data` (str or bytes) into `path` through a temporary file: nothing partial is left."""
    tmp = path + ".tmp"
    try:
        with open(tmp, "wb") as f:
            f.write(data.encode("utf-8") if isinstance(data, str) else data)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


# ---------------------------------------------------------------- PDF

def plain(text):
    """`text` drawn as it is by matplotlib: with mathtext off as it is; else every `$` escaped
    (matplotlib shows an escaped `\\$` as `$`)."""
    return str(text) if MATH_OFF else str(text).replace("$", r"\$")


def text_pages(title, blocks):
    """Pages of monospace tables: blocks = [(heading, rows)]. Every text is user text: plain()."""
    lines = []
    for heading, rows in blocks:
        lines.append(("h", heading))
        if not rows:
            lines.append(("t", "-"))
            continue
        widths = [max(len(str(r[i])) for r in rows) for i in range(len(rows[0]))]
        for r in rows:
            lines.append(("t", "  ".join(str(x).ljust(w) for x, w in zip(r, widths))))
        lines.append(("t", ""))
    per_page = 66  # lines from y = 0.925 down to 0.08 (24 mm above the bottom edge)
    figs = []
    for start in range(0, len(lines), per_page):
        fig = plt.figure(figsize=A4)
        fig.text(0.07, 0.948, plain(title), fontsize=12, weight="bold")
        y = 0.925
        for kind, text in lines[start:start + per_page]:
            if kind == "h":
                fig.text(0.07, y, plain(text), fontsize=9, weight="bold")
            else:
                fig.text(0.07, y, plain(text), fontsize=5.6, family="monospace")
            y -= 0.0128
        figs.append(fig)
    return figs


def write_pdf(c, path, page):
    """`page` (page_html) typeset by weasyprint; without it matplotlib's pages (write_pdf_pages)."""
    try:
        import weasyprint
    except ImportError:
        sys.stderr.write("note: %s drawn with matplotlib: weasyprint is missing (Debian package "
                         "weasyprint, tools/setup.sh installs it)\n" % path)
        tmp = path + ".tmp"
        try:
            write_pdf_pages(c, tmp, title_of(c))
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        return
    # The page's user text is HTML-escaped (page_html). No creation date is written (weasyprint
    # writes dates only from <meta name=dcterms.created>); the embedded font subsets carry a
    # 'modified' time, which fontTools takes from SOURCE_DATE_EPOCH when set (reproducible builds):
    # fixed here, so the PDF is the same byte for byte for the same certificate.
    os.environ.setdefault("SOURCE_DATE_EPOCH", "0")
    write_atomically(path, weasyprint.HTML(string=page).write_pdf())


def write_pdf_pages(c, tmp, title):
    lab = c["lab"]
    with PdfPages(tmp, metadata={"CreationDate": None, "Creator": "aerocal certificate",
                                 "Producer": "matplotlib"}) as pdf:
        statements = [["statement"]] + [[q["statement"]] for q in c["results"]]
        wrapped = [[line] for line in textwrap.wrap(model_text(c), 150)]
        blocks = [("1. Identification, method and data", identification_rows(c)),
                  ("Camera model", wrapped), ("", model_rows(c)),
                  ("2. Results (U = k u_c, ISO GUM / JJF 1059.1)", statements),
                  ("", result_rows(c)),
                  ("3. Uncertainty budget", [[line] for line in textwrap.wrap(type_a_note(c), 150)] or [[""]])]
        blocks += [("budget of " + heading if heading else "", rows) for heading, rows in budget_tables(c)]
        blocks += [("Sources of the components", [[r[0], r[1], r[2], line] for r in source_rows(c)
                                                  for line in (textwrap.wrap(r[3], 90) or [""])])]
        if is_draft(c):
            blocks.insert(0, ("DRAFT: no laboratory file (--lab): not a calibration certificate", [[""]]))
        for fig in text_pages(title, blocks):
            pdf.savefig(fig)
            plt.close(fig)
        for make in (fig_distortion, fig_residuals_correlation):
            fig = plt.figure(figsize=A4)
            fig.text(0.07, 0.948, plain(title), fontsize=12, weight="bold")
            sub = make(c)
            buf = io.BytesIO()
            sub.savefig(buf, format="png", dpi=200)
            plt.close(sub)
            buf.seek(0)
            img = plt.imread(buf)
            # 17 mm margins on A4; a rig's row per head takes the page's height.
            tall = img.shape[0] > img.shape[1]
            ax = fig.add_axes([0.08, 0.05, 0.84, 0.88] if tall else [0.08, 0.45, 0.84, 0.5])
            ax.imshow(img)
            ax.axis("off")
            pdf.savefig(fig)
            plt.close(fig)
        s = lab["signatures"]
        sig = [["calibrated by", "checked by", "approved by"],
               [s["calibrated_by"] or "", s["checked_by"] or "", s["approved_by"] or ""],
               ["signature: ______________", "signature: ______________", "signature: ______________"]]
        blocks = [("6. Stability over image groups", stability_rows(c) or [["no image groups given"]]),
                  ("7. Check points", check_rows(c)),
                  ("8. Comparison with the previous certificate", comparison_rows(c) or [["no previous certificate given"]])]
        if comparison_rows(c):
            blocks.append(("", [[line] for line in textwrap.wrap(COMPARISON_NOTE, 150)]))
        if c.get("dynamic_image_resolution"):
            blocks += [("9. Dynamic image resolution (MTF50, U = k u_c, k = 2)", resolution_edge_rows(c) or [["no edges"]]),
                       ("", resolution_axis_rows(c) or [["no repeated edges of one axis"]]),
                       ("", resolution_bar_rows(c) or [["no bar targets"]]),
                       ("", resolution_star_rows(c) or [["no Siemens stars"]])]
        blocks += [("Findings", [[w] for w in warning_lines(c)] or [["none"]])]
        if not is_draft(c):
            blocks.append(("Signatures", sig))
        for fig in text_pages(title, blocks):
            pdf.savefig(fig)
            plt.close(fig)
        if c.get("dynamic_image_resolution"):
            fig = fig_mtf(c)
            fig.suptitle("9. Dynamic image resolution: MTF curves and bar contrast transfer")
            fig.tight_layout(rect=(0, 0, 1, 0.93))
            pdf.savefig(fig)
            plt.close(fig)


# ResultSchemaVersion("certificate") of calib/core/result_file.h: the version this renderer reads.
SCHEMA_VERSION = 3


def main(argv):
    if len(argv) != 3:
        print("usage: aerocal_certificate.py CERTIFICATE.json OUT_DIR", file=sys.stderr)
        return 2
    try:
        with open(argv[1], encoding="utf-8") as f:
            c = json.load(f)
    except (OSError, ValueError) as e:
        print("error: %s: %s" % (argv[1], e), file=sys.stderr)
        return 2
    if not isinstance(c, dict) or c.get("kind") != "certificate":
        print("error: %s: not a certificate.json (kind must be \"certificate\")" % argv[1], file=sys.stderr)
        return 2
    if c.get("schema_version") != SCHEMA_VERSION or isinstance(c.get("schema_version"), bool):
        print("error: %s: schema_version is %s, expected %d (kind \"certificate\")"
              % (argv[1], json.dumps(c.get("schema_version")), SCHEMA_VERSION), file=sys.stderr)
        return 2
    figures = {"distortion": svg_of(fig_distortion(c)), "residuals": svg_of(fig_residuals_correlation(c))}
    if c.get("dynamic_image_resolution"):
        figures["mtf"] = svg_of(fig_mtf(c))
    page = page_html(c, figures)
    write_atomically(os.path.join(argv[2], "certificate.html"), page)
    write_pdf(c, os.path.join(argv[2], "certificate.pdf"), page)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
