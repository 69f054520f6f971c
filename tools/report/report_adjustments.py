"""Report sections of the adjustments: statistics, comparison, calibration, residual and check maps."""
import report_data as rd
import report_facts as rf
import report_plots as plots
import report_points as points
from report_points import folded as points_folded
from report_html import Cell, esc, figure, fmt, not_available, note, num, raw, table, text, yes_no
from report_sections import anchor

AXES = "XYZ"


def _points_table(a, table_id):
    rows = []
    for which in ("control", "check", "check_controlled"):
        s = rd.point_statistics(a, which)
        if s is None:
            if which != "check_controlled":  # only after data snooping
                rows.append([text(which)] + [text("n/a")] * 12)
            continue
        label = "check, controlled rays only" if which == "check_controlled" else which
        rows.append([text(label), num(s["n"], "d")] + [num(v) for v in s["rmse"]] +
                    [num(s["plan"]), num(s["spatial"])] + [num(v) for v in s["mean"]] + [num(v) for v in s["max"]])
    headers = (["points", "n"] + [f"RMSE {x} [m]" for x in AXES] + ["RMSE planimetric [m]", "RMSE spatial [m]"] +
               [f"mean {x} [m]" for x in AXES] + [f"max |{x}| [m]" for x in AXES])
    return table(table_id, "Control and check points (adjusted minus surveyed)", headers, rows)


def _joint_extras(a, aid):
    out = []
    scope, datum = a.get("mapping_scope"), a.get("datum")
    if scope or datum:
        out.append(note(f"Mappings estimated {esc(scope or 'n/a')}; datum of the focal plane: {esc(datum or 'n/a')}."))
    if a.get("mapping_model"):
        out.append(note(f"Mapping model: {esc(a.get('mapping_model'))} ({esc(a.get('mapping_model_reason') or 'n/a')})."))
    subs = [s for s in rd.listing(a.get("subimages")) if isinstance(s, dict)]
    if subs:
        rows = []
        for s in subs:
            where = [text(s.get("id", "")), text(s.get("exposure", "all")), text(s.get("model", ""))]
            if s.get("base"):  # the datum: held at the camera file's mapping
                rows.append(where + [text("yes"), Cell("all held at the camera file's values (datum)", "text-small")] +
                            [text("-")] * 4)
                continue
            params, sigma = rd.listing(s.get("params")), rd.listing(s.get("sigma"))
            initial = rd.listing(s.get("initial"))
            names = rd.listing(s.get("param_names")) or [f"p{k}" for k in range(len(params))]
            for k, value in enumerate(params):
                v0 = rd.number(initial[k]) if k < len(initial) else None
                v = rd.number(value)
                rows.append(where + [text("no"), text(names[k] if k < len(names) else k), num(v0, ".6g"),
                                     num(v - v0 if None not in (v, v0) else None, ".3g"), num(v, ".6g"),
                                     num(rd.number(sigma[k]) if k < len(sigma) else None, ".3g")])
        opened = " open" if len(rows) <= 40 else ""
        out.append(f"<details{opened}><summary>Refined sub-image mappings ({len(subs)} mappings)</summary>")
        out.append(table(f"{aid}-subimages", "Refined sub-image mappings (plain form, CONVENTIONS.md; "
                         "translations in px)", ["sub-image", "exposure", "model", "base", "parameter",
                                                 "initial", "correction", "estimated", "sigma"], rows))
        out.append("</details>")
    per_exposure = [e for e in rd.listing(a.get("stitching_per_exposure")) if isinstance(e, dict)]
    if per_exposure:
        rows = [[text(e.get("image", "")), num(rd.number(e.get("n_observations")), ".0f"),
                 num(rd.number(e.get("sigma0_before_px"))), num(rd.number(e.get("sigma0_after_px")))]
                for e in per_exposure]
        out.append(table(f"{aid}-stitching-sigma0", "Stitching sigma0 per exposure, before and after the joint "
                         "adjustment", ["exposure", "observations", "sigma0 before [px]", "sigma0 after [px]"], rows))
    corr = [c for c in rd.listing(a.get("mapping_interior_correlations")) if isinstance(c, dict)]
    if "mapping_interior_correlations" in a:
        if corr:
            out.append(table(f"{aid}-correlations", "Correlations above 0.95 between mappings and interior parameters",
                             ["parameter", "parameter", "correlation"],
                             [[text(c.get("a")), text(c.get("b")), num(rd.number(c.get("correlation")), ".3f")]
                              for c in corr]))
        else:
            out.append(note("No correlation between mappings and interior parameters exceeds 0.95."))
    return "".join(out)


def _pair(value, spec):
    values = rd.listing(value)
    return ", ".join(fmt(rd.number(v), spec) for v in values) if values else "n/a"


def _uncontrolled(a, aid):
    """Check points resting on rays data snooping cannot judge (the observations: weak_summary)."""
    out = []
    controlled = a.get("check_controlled")
    points = [p for p in rd.listing(controlled.get("uncontrolled_points"))
              if isinstance(p, dict)] if isinstance(controlled, dict) else []
    if points:
        body = table(f"{aid}-uncontrolled-checks", "Check points resting on rays no test can judge (left out of "
                     "the controlled check RMSE, kept in the check RMSE)",
                     ["point", "rays", "|difference| [m]", "why"],
                     [[text(p.get("point", "")), num(rd.number(p.get("rays")), ".0f"),
                       num(_norm(p.get("difference_m"))), text(p.get("reason", ""))] for p in points],
                     ["flagged"] * len(points))
        out.append(points_folded(f"Check points resting on rays no test can judge: {len(points)}", body,
                                 len(points)))
    return "".join(out)


def _norm(values):
    values = [rd.number(v) for v in rd.listing(values)]
    return None if not values or None in values else sum(v * v for v in values) ** 0.5


def adjustment(a, number, doc=None):
    aid = "adj-" + anchor(a["name"])
    out = [f'<h3 id="{aid}">4.{number} {esc(rd.title(a))}</h3>']
    free = rd.listing(a.get("self_calibration"))
    rows = [["converged", raw(yes_no(a.get("converged")))],
            ["iterations", num(rd.number(a.get("iterations")), ".0f")],
            ["redundancy", num(rd.number(a.get("redundancy")), ".0f")],
            ["sigma0 [1] (a-priori sigmas right: 1)", num(rd.number(a.get("sigma0")))],
            ["sigma0 [px]", num(rd.number(a.get("sigma0_px")))],
            ["sigma0 [um]", num(rd.number(a.get("sigma0_um")), ".3f")],
            ["interior parameters estimated", text(", ".join(map(str, free)) if free else "none (held fixed)")]]
    for key, label in (("n_observations", "observations"), ("n_unknowns", "unknowns")):
        if rd.number(a.get(key)) is not None:
            rows.append([label, num(rd.number(a.get(key)), ".0f")])
    out.append(table(f"{aid}-summary", "Adjustment", ["item", "value"], rows))
    out.append(_points_table(a, f"{aid}-points"))
    out.append(points.points_tables(a, aid))
    geo = rf.geometry(doc, a) if doc else None
    strip_of = {image: str(k) for k, strip in enumerate(geo["strips"] if geo else [], 1) for image in strip}
    out.append(points.exposures_table(a, aid, strip_of))
    out.append(points.rejected_table(a, aid))
    out.append(_uncontrolled(a, aid))
    out.append(points.weak_summary(a, aid))
    for w in rd.listing(a.get("warnings")):
        message = w.get("message") if isinstance(w, dict) else w
        out.append(f'<p class="na"><span class="bad">warning</span>: {esc(message)}</p>')
    det = a.get("determinability")
    if isinstance(det, dict):
        for w in rd.listing(det.get("warnings")):
            out.append(f'<p class="na">warning: {esc(w)}</p>')
        for h in rd.listing(det.get("high_correlations")):
            if isinstance(h, dict):
                out.append(note(f"correlation {esc(h.get('a'))} / {esc(h.get('b'))}: "
                                f"{fmt(rd.number(h.get('correlation')), '.3f')}"))
    out.append(_joint_extras(a, aid))
    return "".join(out)


def adjustments(doc):
    out = ['<h2 id="adjustments">4. Adjustments</h2>']
    adjs = rd.adjustments(doc)
    if not adjs:
        return out[0] + not_available("Adjustments")
    for k, a in enumerate(adjs, 1):
        try:
            out.append(adjustment(a, k, doc))
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as e:
            out.append(not_available(f"{rd.title(a)} (unreadable: {e})"))
    return "".join(out)


def left_out(doc):
    out = ['<h2 id="left-out">5. Left out: images, points and observations the adjustments did not use</h2>']
    rows = points.left_out(doc)
    if not rows:
        return out[0] + note("Nothing was left out: every image, point and observation was used.")
    out.append(table("left-out-table", "Left out, each with the reason", ["adjustments", "kind", "what", "why"],
                     [[text(t), text(k), text(w), Cell(esc(r), "text-small")] for t, k, w, r in rows]))
    return "".join(out)


def comparison(doc):
    out = ['<h2 id="comparison">6. Comparison of the adjustments</h2>']
    adjs = rd.adjustments(doc)
    if not adjs:
        return out[0] + not_available("Comparison")
    stats = [(rd.point_statistics(a, "control"), rd.point_statistics(a, "check")) for a in adjs]

    def row(label, values, spec=".4f"):
        return [text(label)] + [num(v, spec) for v in values]

    def stat(which, key, k=None):
        vals = []
        for control, check in stats:
            s = control if which == "control" else check
            vals.append(None if s is None else (s[key][k] if k is not None else s[key]))
        return vals

    rows = [row("sigma0 [1]", [rd.number(a.get("sigma0")) for a in adjs]),
            row("sigma0 [px]", [rd.number(a.get("sigma0_px")) for a in adjs]),
            row("sigma0 [um]", [rd.number(a.get("sigma0_um")) for a in adjs], ".3f"),
            row("redundancy", [rd.number(a.get("redundancy")) for a in adjs], ".0f"),
            row("iterations", [rd.number(a.get("iterations")) for a in adjs], ".0f"),
            [text("converged")] + [raw(yes_no(a.get("converged"))) for a in adjs],
            row("control points", stat("control", "n"), ".0f")]
    rows += [row(f"control RMSE {x} [m]", stat("control", "rmse", k)) for k, x in enumerate(AXES)]
    rows.append(row("check points", stat("check", "n"), ".0f"))
    rows += [row(f"check RMSE {x} [m]", stat("check", "rmse", k)) for k, x in enumerate(AXES)]
    rows += [row("check RMSE planimetric [m]", stat("check", "plan")),
             row("check RMSE spatial [m]", stat("check", "spatial"))]
    rows += [row(f"check mean {x} [m]", stat("check", "mean", k)) for k, x in enumerate(AXES)]
    rows += [row(f"check max |{x}| [m]", stat("check", "max", k)) for k, x in enumerate(AXES)]
    out.append(table("comparison-table", "The adjustments side by side", [""] + [rd.title(a) for a in adjs], rows))
    return "".join(out)


def _calibration_table(a, camera, table_id, parameters):
    initial, estimated = rd.interior(camera, "initial"), rd.interior(camera, "estimated")
    sigma = camera.get("sigma") if isinstance(camera.get("sigma"), dict) else {}
    rows = []
    for name, unit in parameters:
        length = unit in ("mm", "px")  # lengths in fixed point, coefficients in exponent form
        spec = ".5f" if length else ".4e"
        v0, v = initial.get(name), estimated.get(name)
        corr = v - v0 if None not in (v0, v) else None
        s = rd.number(sigma.get(name))
        free = name in sigma
        rows.append([text(name), text(unit), num(v0, spec), num(corr, spec if length else ".3e"), num(v, spec),
                     num(s, ".2e") if free else text("fixed"),
                     num(abs(corr) / s if corr is not None and s else None, ".1f")])
    return table(table_id, f"Camera {camera.get('id', '?')}: interior orientation ({rd.title(a)})",
                 ["parameter", "unit", "initial", "correction", "estimated", "sigma", "|correction| / sigma"], rows)


def calibration(doc):
    out = ['<h2 id="calibration">7. Calibration</h2>']
    adjs = rd.adjustments(doc)
    estimating = [a for a in adjs if rd.estimates_interior(a)]
    fixed = [rd.title(a) for a in adjs if not rd.estimates_interior(a)]
    if fixed:
        out.append(note(f"{esc(', '.join(fixed))}: interior orientation held at the camera file's values."))
    if not estimating:
        return "".join(out) + not_available("Calibration (no adjustment estimated interior parameters)")
    model = rd.camera_model_name(doc)
    out.append(note(f"correction = estimated - initial. Parameters and units of the camera model {esc(model)} "
                    "(the result's camera_model table; CONVENTIONS.md). Parameters held fixed show 'fixed'."))
    parameters = rd.interior_parameters(doc)
    for a in estimating:
        for cam in rd.cameras(a):
            out.append(_calibration_table(a, cam, f"calib-{anchor(a['name'])}-{anchor(cam.get('id', 'camera'))}",
                                          parameters))
    out.append('<h3 id="distortion">7.1 Distortion curves</h3>')
    if model != "brown_fraser_10":
        out.append(not_available(f"Distortion curves (drawn for the 10-parameter model's terms; the camera is "
                                 f"in the model {model})"))
    else:
        out.append(_distortion(doc, adjs, estimating))
    return "".join(out)


def _distortion(doc, adjs, estimating):
    fmt_info = rd.camera_format(doc)
    if not fmt_info:
        return not_available("Distortion curves (image format unknown)")
    w, h, p = fmt_info
    half_w, half_h = w * p / 2, h * p / 2
    out = []
    camera_ids = []
    for a in adjs:
        for cam in rd.cameras(a):
            if cam.get("id") not in camera_ids:
                camera_ids.append(cam.get("id"))
    for cid in camera_ids:
        curves = []
        initial = next((rd.interior(c, "initial") for a in adjs for c in rd.cameras(a) if c.get("id") == cid), {})
        if initial:
            curves.append(("initial (camera file)", initial, True))
        for a in estimating:
            for cam in rd.cameras(a):
                if cam.get("id") == cid and rd.interior(cam, "estimated"):
                    curves.append((f"estimated: {rd.title(a)}", rd.interior(cam, "estimated"), False))
        if len(curves) < 1:
            continue
        png = plots.distortion_curves(cid, curves, half_w, half_h)
        out.append(figure(f"distortion-{anchor(cid)}", png, f"distortion curves of camera {cid}",
                          f"Camera {esc(cid)}: radial distortion dr(r) = r (K1 r^2 + K2 r^4 + K3 r^6) and decentring "
                          f"distortion P(r) = sqrt(P1^2 + P2^2) r^2, in um, from the format centre to the corner "
                          f"(half-diagonal {((half_w ** 2 + half_h ** 2) ** 0.5):.1f} mm); dashed: initial values."))
    return "".join(out) or not_available("Distortion curves")


def residual_plot(doc):
    out = ['<h2 id="residuals">8. Image residuals over the format</h2>']
    fmt_info = rd.camera_format(doc)
    adjs = rd.adjustments(doc)
    panels = [(rd.title(a), rd.residuals(a)) for a in adjs]
    n_rejected = sum(1 for a in adjs for r in rd.listing(a.get("residuals"))
                     if isinstance(r, dict) and r.get("used") is False)
    panels = [(t, r) for t, r in panels if r]
    if not fmt_info or not panels:
        return out[0] + not_available("Image residuals" if fmt_info else "Image residuals (image format unknown)")
    w, h, p = fmt_info
    png, facts = plots.residual_vectors(panels, w, h, p)
    grid = facts["grid"]
    how = (f"mean residual per cell of a {grid[0]} x {grid[1]} grid" if grid else "every residual")
    out.append(figure("residual-plot", png, "residual vectors over the image format",
                      f"Image residuals in photo coordinates (x right, y up, mm; the grey frame is the image "
                      f"format): {how}, exaggerated {facts['exaggeration']:g} times (the key arrow is "
                      f"{facts['key_px']:g} px); the same scale in every panel. Only the observations each "
                      f"adjustment used are drawn: the {n_rejected} rejected are listed apart with their w (section 4, "
                      f"'Observations rejected'), so a blunder never sets the scale. A systematic pattern means the "
                      f"camera model leaves distortion unmodelled."))
    return "".join(out)


def check_map(doc):
    out = ['<h2 id="check-map">9. Check-point errors</h2>']
    panels = [(rd.title(a), rd.point_errors(a, "check"), rd.point_errors(a, "control")) for a in rd.adjustments(doc)]
    panels = [p for p in panels if p[1]]
    if not panels:
        return out[0] + not_available("Check-point errors")
    png, facts = plots.check_point_map(panels)
    out.append(figure("check-map", png, "map of check-point errors",
                      f"Check-point errors (adjusted minus surveyed) in the object frame: planimetric errors as "
                      f"vectors exaggerated {facts['exaggeration']:g} times (the key arrow is {facts['key_m']:g} m), "
                      f"Z error as colour (-{facts['z_lim']:.3f} .. +{facts['z_lim']:.3f} m); the same scales in "
                      f"every panel; triangles: control points."))
    return "".join(out)
