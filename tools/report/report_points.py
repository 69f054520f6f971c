"""Per-point, per-exposure and per-observation tables of one adjustment (issue 33 item 1).

Every row names its point, image or observation; what the adjustment did not use is listed apart
with the reason and the test statistic w that decided it, so that no figure of the report hides a
rejected blunder and no left-out element goes unnamed.
"""
import math

import report_data as rd
from report_html import Cell, esc, fmt, note, num, table, text

FOLD_ROWS = 25  # longer tables are folded (<details>) so that the page stays readable


def folded(summary_html, body_html, rows):
    """body in a <details> element, open when it is short."""
    opened = " open" if rows <= FOLD_ROWS else ""
    return f"<details{opened}><summary>{summary_html}</summary>{body_html}</details>"


def _norm(values):
    return None if None in values else math.sqrt(sum(v * v for v in values))


def point_rows(adjustment, which):
    """[{point, rays, d: [dX, dY, dZ], plan, spatial, status, reason, w}] of the control or check
    points, with those data snooping left out (control) or that rest on untestable rays (check)."""
    block = rd.get(adjustment, which) or {}
    rows = []
    for p in rd.listing(rd.get(block, "points")):
        if not isinstance(p, dict):
            continue
        d = rd.triple(p.get("difference_m"))
        reason = p.get("uncontrolled") or ""
        rows.append({"point": str(p.get("point", "")), "rays": rd.number(p.get("rays")), "d": d,
                     "plan": _norm(d[:2]), "spatial": _norm(d), "w": None,
                     "status": "used, untestable rays" if reason else "used", "reason": reason})
    if which == "control":
        for left in rd.listing(adjustment.get("control_left_out")):
            if not isinstance(left, dict):
                continue
            d = rd.triple(left.get("difference_m"))
            parts = left.get("components") if isinstance(left.get("components"), dict) else {}
            w = rd.number(left.get("w"))
            names = " and ".join(str(c) for c in parts) or "survey"
            rows.append({"point": str(left.get("point", "")), "rays": rd.number(left.get("rays")), "d": d,
                         "plan": _norm(d[:2]), "spatial": _norm(d), "w": w, "status": "rejected",
                         "reason": f"{names} of the survey left out by data snooping"})
    return rows


def points_tables(adjustment, aid):
    out = []
    for which, title in (("control", "Control points"), ("check", "Check points")):
        rows = point_rows(adjustment, which)
        if not rows:
            continue
        cells = [[text(r["point"]), num(r["rays"], ".0f")] + [num(v) for v in r["d"]] +
                 [num(r["plan"]), num(r["spatial"]), num(r["w"], ".1f") if r["w"] is not None else text("-"), text(r["status"]),
                  Cell(esc(r["reason"]), "text-small")] for r in rows]
        classes = ["flagged" if r["status"] != "used" else "" for r in rows]
        body = table(f"{aid}-{which}-points", f"{title}: adjusted minus surveyed, metres of the adjustment frame",
                     ["point", "rays", "dX [m]", "dY [m]", "dZ [m]", "plan [m]", "spatial [m]", "w",
                      "status", "why"], cells, classes)
        out.append(folded(f"{title}: {len(rows)} ({sum(1 for r in rows if r['status'] == 'rejected')} rejected)",
                          body, len(rows)))
    if out:
        out.append(note("w: the standardised residual of the test that rejected a control survey; check points "
                        "are not observations of the adjustment and have no w. Red rows: rejected, or resting on "
                        "rays no test can judge."))
    return "".join(out)


def image_rms(adjustment):
    """{image: (n used, RMS of the used residuals in px)} (sqrt of the mean of vcol^2 + vrow^2 over 2)."""
    sums = {}
    for r in rd.listing(adjustment.get("residuals")):
        if not isinstance(r, dict) or r.get("used") is False:
            continue
        v = [rd.number(r.get("v_col_px")), rd.number(r.get("v_row_px"))]
        if None in v:
            continue
        n, s = sums.get(str(r.get("image")), (0, 0.0))
        sums[str(r.get("image"))] = (n + 1, s + v[0] ** 2 + v[1] ** 2)
    return {k: (n, math.sqrt(s / (2 * n))) for k, (n, s) in sums.items()}


def exposures_table(adjustment, aid, strips):
    exposures = [e for e in rd.listing(adjustment.get("exposures")) if isinstance(e, dict)]
    if not exposures:
        return ""
    rms = image_rms(adjustment)
    rows, classes = [], []
    for e in exposures:
        image = str(e.get("image", ""))
        sigma = e.get("sigma") if isinstance(e.get("sigma"), dict) else {}
        cells = [text(image), text(strips.get(image, "-"))]
        for key, spec in (("X", ".3f"), ("Y", ".3f"), ("Z", ".3f"), ("omega", ".4f"), ("phi", ".4f"),
                          ("kappa", ".4f")):
            # The value over its sigma in one cell: half the columns, so the table fits a page.
            s = rd.number(sigma.get(key))
            cells.append(Cell(f"{fmt(rd.number(e.get(key)), spec)}<br><small>&plusmn; {fmt(s, '.3g')}</small>"
                              if s is not None else fmt(rd.number(e.get(key)), spec), "num"))
        n, v = rms.get(image, (0, None))
        cells += [num(n, "d"), num(v, ".3f"), text("yes" if e.get("used") is not False else "no: left out")]
        rows.append(cells)
        classes.append("" if e.get("used") is not False else "flagged")
    body = table(f"{aid}-exposures", "Exposures: adjusted orientation, each value over its sigma (no sigma "
                 "where not estimated), residual RMS of the used observations per image",
                 ["image", "strip", "X [m]", "Y [m]", "Z [m]", "omega [deg]", "phi [deg]", "kappa [deg]",
                  "obs. used", "RMS [px]", "used"], rows, classes)
    return folded(f"Exposures: {len(rows)} ({sum(1 for c in classes if c)} left out)", body, len(rows))


def rejected_table(adjustment, aid):
    rejected = [r for r in rd.listing(adjustment.get("rejected")) if isinstance(r, dict)]
    if not rejected:
        return note("No observation rejected as a gross error.") if "rejected" in adjustment else ""
    rows = [[text(r.get("image", "")), text(r.get("point", "")),
             text(", ".join(fmt(rd.number(v), ".1f") for v in rd.listing(r.get("measured_px"))) or "n/a"),
             num(rd.number(r.get("residual_px")), ".2f"), num(rd.number(r.get("w")), ".1f"),
             text(r.get("by") or "data snooping")] for r in rejected]
    return table(f"{aid}-rejected", "Observations rejected as gross errors (not used: not in the residual "
                 "statistics or plots)", ["image", "point", "measured (col, row) [px]", "residual [px]",
                                          "standardised residual w", "rejected by"], rows)


def weak_summary(adjustment, aid):
    """The weakly controlled observations summarised (count, worst, where), the list folded."""
    snooping = adjustment.get("snooping") if isinstance(adjustment.get("snooping"), dict) else {}
    obs = [u for u in rd.listing(snooping.get("uncontrolled")) if isinstance(u, dict)]
    if not obs:
        return ""

    def smallest_r(u):
        r = [rd.number(v) for v in rd.listing(u.get("r"))]
        return min((v for v in r if v is not None), default=1.0)

    worst = min(obs, key=smallest_r)
    images = sorted({str(u.get("image", "")) for u in obs})
    points = sorted({str(u.get("point", "")) for u in obs})
    untestable = sum(1 for u in obs if u.get("untestable"))
    limit = rd.number(snooping.get("min_redundancy"))
    summary = (f"{len(obs)} observation(s) weakly controlled (redundancy number r below "
               f"{fmt(limit, 'g')}), {untestable} with r = 0 where a blunder is invisible; worst: image "
               f"{esc(worst.get('image'))} point {esc(worst.get('point'))} (r = {fmt(smallest_r(worst), '.3f')}); "
               f"in {len(images)} image(s) ({esc(', '.join(images[:8]))}{', ...' if len(images) > 8 else ''}) on "
               f"{len(points)} point(s) ({esc(', '.join(points[:8]))}{', ...' if len(points) > 8 else ''})")
    rows = [[text(u.get("image", "")), text(u.get("point", "")), num(rd.number(u.get("rays")), ".0f"),
             text(", ".join(fmt(rd.number(v), ".2f") for v in rd.listing(u.get("r")))),
             text(", ".join(fmt(rd.number(v), ".3g") for v in rd.listing(u.get("mdb_px")))),
             Cell(esc(u.get("reason", "")), "text-small")] for u in obs]
    body = table(f"{aid}-uncontrolled", "Observations with a redundancy number below the limit (a blunder there "
                 "is not found, or only above its MDB)", ["image", "point", "rays", "r (x, y)",
                                                          "MDB (x, y) [px]", "why"], rows)
    return f'<p class="note" id="{aid}-weak-summary">{summary}.</p>' + \
        f"<details><summary>Full list ({len(obs)})</summary>{body}</details>"


def left_out(doc):
    """[(adjustment titles, kind, what, reason)] of every image, point and observation left out;
    one row for what several adjustments left out for the same reason."""
    rows = {}
    for t, kind, what, why in _left_out_per_adjustment(doc):
        rows.setdefault((kind, what, why), []).append(t)
    return [(", ".join(titles), kind, what, why) for (kind, what, why), titles in rows.items()]


def _left_out_per_adjustment(doc):
    out = []
    for a in rd.adjustments(doc):
        t = rd.title(a)
        for e in rd.listing(a.get("exposures")):
            if isinstance(e, dict) and e.get("used") is False:
                why = next((n for n in map(str, rd.listing(a.get("notes")))
                            if f"image {e.get('image')} " in n and "left out" in n), "no usable observations")
                out.append((t, "image", str(e.get("image")), why))
        for n in map(str, rd.listing(a.get("notes"))):
            if "point" in n and ("not used" in n or "left out" in n) and not n.startswith("image "):
                out.append((t, "point", n.split(" has ")[0].split(" is ")[0], n))
        for r in point_rows(a, "control"):
            if r["status"] == "rejected":
                out.append((t, "control survey", r["point"], f"{r['reason']} (w = {fmt(r['w'], '.1f')})"))
        for r in rd.listing(a.get("rejected")):
            if isinstance(r, dict):
                out.append((t, "observation", f"image {r.get('image')} point {r.get('point')}",
                            f"gross error, rejected by {r.get('by') or 'data snooping'} "
                            f"(residual {fmt(rd.number(r.get('residual_px')), '.1f')} px, "
                            f"w = {fmt(rd.number(r.get('w')), '.1f')})"))
    return out
