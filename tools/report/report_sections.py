"""The sections of the flight report, each a function of the result document returning HTML.

A section whose data is missing says "not available"; it never stops the others.
"""
import re
import statistics

import report_data as rd
import report_facts as rf
from report_points import folded
import report_plots as plots
from report_html import (Cell, esc, figure, fmt, not_available, note, num, raw, table, text,
                         yes_no)

def anchor(name):
    return re.sub(r"[^a-z0-9]+", "-", str(name).lower()).strip("-") or "x"

def _mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else None

# ---- summary --------------------------------------------------------------------------------

def summary(doc):
    out = ['<h2 id="summary">1. Summary</h2>', rf.verdict(doc)]

    steps, classes = [], []
    stitching = rd.get(doc, "stitching")
    if isinstance(stitching, dict):
        n = rd.number(rd.get(stitching, "n_frames")) or len(rd.frames(stitching)) or None
        steps.append(["Stitching (per exposure)", raw(yes_no(stitching.get("converged"))),
                      num(rd.number(stitching.get("sigma0"))), num(rd.number(stitching.get("sigma0_px"))),
                      text(f"model {stitching.get('model', 'n/a')}, {fmt(n, 'd')} exposures")])
        classes.append("" if stitching.get("converged") is not False else "flagged")
    warnings = []  # (step, sentence): shown in red under the table
    for a in rd.adjustments(doc):
        check = rd.point_statistics(a, "check")
        key = f"check points: {fmt(check['n'], 'd')}, spatial RMSE {fmt(check['spatial'])} m" if check else ""
        if a.get("mapping_model"):
            key += f"; mappings {a.get('mapping_model')}"
        named = rd.listing(a.get("warnings"))  # [{name, subject, value, limit, message}]
        if named:
            key += f"; {len(named)} warning(s)"
        for w in named:
            warnings.append((rd.title(a), "warning: " + str(w.get("message") if isinstance(w, dict) else w)))
        valid = a.get("valid") is not False and a.get("converged") is not False
        steps.append([text(rd.title(a)), raw(yes_no(a.get("converged"))), raw(yes_no(valid)),
                      num(rd.number(a.get("sigma0"))), num(rd.number(a.get("sigma0_px"))), text(key)])
        classes.append("" if valid else "flagged")
        for reason in a.get("invalid_reasons") or []:
            warnings.append((rd.title(a), "not valid: " + str(reason)))
        snooping = a.get("snooping") or {}
        if snooping.get("model_error_suspected"):
            evidence = "; ".join(str(e) for e in snooping.get("model_error_evidence") or [])
            warnings.append((rd.title(a), f"model error suspected ({evidence}). "
                                          f"{snooping.get('suggestion', '')}"))
        for f in snooping.get("findings") or []:
            if "cannot be told apart" in str(f) or "suspected blunder" in str(f):
                warnings.append((rd.title(a), str(f)))
    if steps:
        for v in [stitching] if isinstance(stitching, dict) else []:
            steps[0].insert(2, raw(yes_no(v.get("converged") is not False)))
        out.append(table("summary-steps", "What ran",
                         ["step", "converged", "valid", "sigma0 [1]", "sigma0 [px]", "key figures"], steps,
                         classes))
        for f in rd.get(doc, "failures") or []:
            warnings.insert(0, (f.get("step", "?"), str(f.get("reason", ""))))
        all_ok = all(c == "" for c in classes) and rd.get(doc, "valid") is not False
        if not all_ok:
            out.append(note('<span class="bad">At least one step did not converge or is not valid: its figures '
                            "are not a valid calibration, and no calibrated camera was written.</span>"))
        if warnings:
            out.append('<ul class="warnings">' + "".join(
                f'<li><span class="bad">{esc(step)}: {esc(sentence)}</span></li>' for step, sentence in warnings)
                + "</ul>")
    else:
        out.append(not_available("Steps of the workflow"))
    out.append(_camera_written(doc))
    tips = rf.advice(doc)
    out.append('<h3 id="advice">Advice for this block</h3>' + (
        '<ul class="advice">' + "".join(f"<li>{esc(t)}</li>" for t in tips) + "</ul>" if tips else
        note("Nothing to add: the block is controlled, checked and free of rejected observations.")))
    return "".join(out)


def _camera_written(doc):
    written = doc.get("camera_written_from")
    if isinstance(written, dict) and written.get("adjustment"):
        names = {a.get("name"): rd.title(a) for a in rd.adjustments(doc)}
        return note(f"<b>The written camera</b> comes from the {esc(names.get(written['adjustment'], written['adjustment']))}: "
                    f"{esc(written.get('reason', ''))}.")
    if "camera_written_from" in doc:
        return note("<b>No camera was written</b>: the result is not valid.")
    return note("Which adjustment a written camera comes from: not stated in this result.")


# ---- stitching ------------------------------------------------------------------------------

def _model_order(frames):
    order = []
    for f in frames:
        for c in rd.candidates(f):
            if c["model"] not in order:
                order.append(c["model"])
    return order

def _test_text(test):
    if not test or rd.number(test.get("F")) is None:
        return ""
    f, fc = rd.number(test.get("F")), rd.number(test.get("F_critical"))
    sign = ">" if test.get("significant") else "<="
    return f"F = {fmt(f, '.3g')} {sign} {fmt(fc, '.3g')}"

def _model_comparison(stitching, frames, order):
    chosen_counts = {}
    for f in frames:
        chosen = rd.get(rd.model_choice(f), "chosen") or f.get("model")
        chosen_counts[chosen] = chosen_counts.get(chosen, 0) + 1
    rows, classes = [], []
    for model in order:
        cands = [c for f in frames for c in rd.candidates(f) if c["model"] == model]
        det = [c for c in cands if c["determinable"]]
        tested = [c["test"] for c in det if c["test"] and rd.number(c["test"].get("F")) is not None]
        fs = [rd.number(t.get("F")) for t in tested]
        against = sorted({str(t.get("against")) for t in tested if t.get("against")})
        rows.append([text(model), num(len(det), "d"), num(chosen_counts.get(model, 0), "d"),
                     num(_mean([c["sigma0"] for c in det])), num(_mean([c["sigma0_px"] for c in det])),
                     num(_mean([c["redundancy"] for c in det]), ".0f"), text(", ".join(against) or "-"),
                     num(statistics.median(fs) if fs else None, ".3g"),
                     text(f"{min(fs):.3g} .. {max(fs):.3g}" if fs else "-"),
                     num(statistics.median([rd.number(t.get("F_critical")) or 0 for t in tested])
                         if tested else None, ".3g"),
                     text(f"{sum(1 for t in tested if t.get('significant'))} of {len(tested)}" if tested else "-")])
        classes.append("chosen" if model == stitching.get("model") else "")
    headers = ["model", "exposures determinable", "chosen in exposures", "mean sigma0 [1]",
               "mean sigma0 [px]", "mean redundancy", "tested against", "median F", "F range",
               "median F critical", "significant in"]
    out = [table("stitch-model-comparison", "Model comparison over the flight", headers, rows, classes)]
    choice = rd.model_choice(frames[0]) if frames else {}
    test = rd.get(choice, "test")
    alpha = rd.number(rd.get(choice, "alpha"))
    reported = stitching.get("model")
    why = (f"The flight's mapping model is <b>{esc(reported)}</b>: the model chosen in most exposures "
           f"({chosen_counts.get(reported, 0)} of {len(frames)}). " if reported else "")
    if test:
        why += f"Each exposure's choice: {esc(test)}" + (f" (alpha {fmt(alpha, 'g')})" if alpha else "") + \
               "; the simplest model that no richer model improves significantly is chosen."
    out.append(note(why))
    return "".join(out)

def _short_reason(chosen, candidates):
    """The decisive step of the choice: the next richer model tested against the chosen one."""
    richer = [c for c in candidates if c["test"] and c["test"].get("against") == chosen]
    if richer:
        c = richer[0]
        verdict = "significant" if c["test"].get("significant") else "not significant"
        return f"{c['model']} against {chosen}: {_test_text(c['test'])} ({verdict})"
    tested = [c for c in candidates if c["model"] == chosen and c["test"]]
    if tested:
        verdict = "significant" if tested[0]["test"].get("significant") else "not significant"
        return (f"{chosen} against {tested[0]['test'].get('against')}: {_test_text(tested[0]['test'])} "
                f"({verdict}); no richer model tested")
    return ""


def _model_choice_per_frame(frames, order, flags_by_frame, reported):
    rows, classes = [], []
    for f in frames:
        frame = str(f.get("frame", "?"))
        chosen = rd.get(rd.model_choice(f), "chosen") or f.get("model")
        by_model = {c["model"]: c for c in rd.candidates(f)}
        row = [text(frame)]
        for model in order:
            c = by_model.get(model)
            if c is None:
                row.append(text("-"))
            elif not c["determinable"]:
                row.append(Cell(f'not determinable<br><small>{esc(c.get("refusal") or "")}</small>', "text-small"))
            else:
                mark = "<b>" if model == chosen else ""
                end = "</b>" if model == chosen else ""
                row.append(Cell(f"{mark}{fmt(c['sigma0_px'])}{end}<br><small>r = {fmt(c['redundancy'], '.0f')}"
                                f"{'; ' + esc(_test_text(c['test'])) if _test_text(c['test']) else ''}</small>",
                                "num"))
        reason = rd.get(rd.model_choice(f), "reason") or ""
        short = _short_reason(chosen, rd.candidates(f)) or reason
        why = esc(short) if short == reason else \
            f"{esc(short)}<details><summary>full reasoning</summary>{esc(reason)}</details>"
        row += [text(chosen or "n/a"), raw(yes_no(f.get("converged"))), Cell(why, "text-small"),
                text(", ".join(m or "flight" for m in flags_by_frame.get(frame, [])) or "-")]
        rows.append(row)
        under = flags_by_frame.get(frame, [])
        classes.append("flagged" if reported in under or "" in under else "")
    headers = ["exposure"] + [f"{m}: sigma0 [px]" for m in order] + ["chosen", "converged", "why",
                                                                     "flagged under"]
    return (folded(f"Model choice per exposure: {len(rows)} exposures",
                   table("stitch-model-choice", "Model choice per exposure (sigma0 in px, redundancy r, "
                         "F test against the next simpler model; chosen model in bold)", headers, rows, classes),
                   len(rows)) +
            note(f"'flagged under': models whose stability test flags the exposure (next table); rows in red "
                 f"are flagged under the flight's model ({esc(reported)})."))

def _stability(stitching, frames):
    entries = rd.stability_models(stitching)
    stability = rd.get(stitching, "stability") or {}
    out = []
    if entries:
        rows, classes = [], []
        for m in entries:
            flags = rd.flagged(m)
            flag_html = "<br>".join(f"<b>{esc(fr)}</b>: {esc('; '.join(reasons))}" for fr, reasons in flags) or "none"
            rows.append([text(m["model"]), num(rd.number(m.get("n_frames")), "d"),
                         num(rd.number(m.get("mean_sigma0"))), num(rd.number(m.get("std_sigma0"))),
                         num(rd.number(m.get("mean_sigma0_px"))), num(rd.number(m.get("std_sigma0_px"))),
                         Cell(flag_html, "text-small")])
            classes.append("chosen" if m["model"] == stitching.get("model") else "")
        out.append(table("stitch-stability", "Flight stability per model", [
            "model", "exposures", "mean sigma0 [1]", "std sigma0 [1]", "mean sigma0 [px]", "std sigma0 [px]",
            "flagged exposures (reason)"], rows, classes))
        out.append(note("A frame is flagged when its sigma0 or its mappings differ from the other frames "
                        "more than the reported precision allows. Green row: the flight's model."))
        reported = next((m for m in entries if m["model"] == stitching.get("model")), None)
        params = [p for p in rd.listing(rd.get(reported, "parameters")) if isinstance(p, dict)]
        if params:
            rows = []
            for p in params:
                std, sig = rd.number(p.get("std")), rd.number(p.get("mean_sigma"))
                rows.append([text(p.get("subimage", "")), text(p.get("name", "")), num(rd.number(p.get("mean")), ".6g"),
                             num(std, ".3g"), num(sig, ".3g"), num(std / sig if std is not None and sig else None, ".2f")])
            out.append('<details><summary>Mapping parameters over the flight '
                       f'({esc(stitching.get("model"))}, {len(params)} parameters)</summary>')
            out.append(table("stitch-parameter-stability", "Mapping parameters over the flight",
                             ["sub-image", "parameter", "mean", "std over exposures", "mean reported sigma",
                              "std / sigma"], rows))
            out.append(note("std / sigma near 1: the reported precision is realistic."))
            out.append("</details>")
    elif rd.number(stability.get("mean_sigma0_px")) is not None:
        out.append(table("stitch-stability", "Flight stability", ["mean sigma0 [px]", "std sigma0 [px]"],
                         [[num(rd.number(stability.get("mean_sigma0_px"))),
                           num(rd.number(stability.get("std_sigma0_px")))]]))
    else:
        out.append(not_available("Flight stability"))
    return "".join(out)

def _sigma0_plot(stitching, frames, order, flagged):
    if not frames:
        return not_available("Plot of sigma0 per exposure")
    series = {m: [] for m in order}
    chosen = []
    for f in frames:
        by_model = {c["model"]: c for c in rd.candidates(f)}
        for m in order:
            c = by_model.get(m)
            series[m].append(c["sigma0_px"] if c and c["determinable"] else None)
        chosen.append((str(f.get("frame", "?")), rd.get(rd.model_choice(f), "chosen") or f.get("model"),
                       rd.number(f.get("sigma0_px"))))
    if all(v is None for _, _, v in chosen):
        return not_available("Plot of sigma0 per exposure")
    stability = rd.get(stitching, "stability") or {}
    mean = rd.number(stability.get("mean_sigma0_px"))
    mean_line = (f"flight mean ({stitching.get('model')})", mean) if mean is not None else None
    png = plots.sigma0_per_exposure(series, chosen, flagged, mean_line)
    return figure("stitch-sigma0-plot", png, "sigma0 per exposure",
                  "Stitching sigma0 (px) of every exposure for each candidate model; the circle marks the "
                  "model chosen for the exposure, a red cross an exposure flagged by the stability test of the "
                  "flight's model; the dashed line is the flight mean of that model.")

def stitching(doc):
    out = ['<h2 id="stitching">3. Stitching of the sub-images</h2>']
    s = rd.get(doc, "stitching")
    if doc.get("kind") == "adjust":
        return out[0] + note("An adjust run has no stitching step (its observations are in the virtual image, "
                             "or the joint adjustment refines the mappings: section 4).")
    if not isinstance(s, dict):
        return out[0] + not_available("Stitching")
    frames = rd.frames(s)
    rows = [["mapping model of the flight", text(s.get("model", "n/a"))],
            ["exposures", num(rd.number(s.get("n_frames")) or len(frames), "d")],
            ["sigma0 [1]", num(rd.number(s.get("sigma0")))], ["sigma0 [px]", num(rd.number(s.get("sigma0_px")))],
            ["redundancy", num(rd.number(s.get("redundancy")), ".0f")], ["converged", raw(yes_no(s.get("converged")))]]
    out.append(table("stitch-summary", "Stitching of the flight (all exposures pooled)", ["item", "value"], rows))
    order = _model_order(frames)
    flags_by_frame = rd.flags_by_frame(s)
    flagged = {f for f, models in flags_by_frame.items() if s.get("model") in models or "" in models}
    out.append('<h3 id="stitch-models">3.1 Model comparison</h3>')
    if order:
        out.append(_model_comparison(s, frames, order))
        out.append(_model_choice_per_frame(frames, order, flags_by_frame, s.get("model")))
    else:
        out.append(not_available("Model comparison"))
    out.append('<h3 id="stitch-flight-stability">3.2 Flight stability</h3>')
    out.append(_stability(s, frames))
    out.append('<h3 id="stitch-sigma0">3.3 sigma0 per exposure</h3>')
    out.append(_sigma0_plot(s, frames, order, flagged))
    return "".join(out)
