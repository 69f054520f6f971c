"""Section 10 of the report: the dynamic image resolution (`aerocal flight --quality Q.json`).

Every number is the one C++ wrote into result.json's `dynamic_image_resolution`
(tools/dynamic_resolution.h, the certificate's section): the edge regions measured, MTF50 with U
(k = 2) per image and axis, the resampling loss (virtual image against the raw sub-images' mean,
and per edge and sub-image where the edges were found from targets in the raw sub-images), the map
of MTF50 across the format (the edges' positions in the virtual image) and the limiting resolution
of bar targets and Siemens stars. Nothing is recomputed here.
"""
import os

import report_data as rd
import report_plots as plots
from report_html import esc, figure, note, num, table, text
from report_points import folded


def _image(entry):
    """Which image a result was measured in: the sub-image id, 'virtual', else the file's name."""
    kind = rd.get(entry, "image_kind")
    if kind == "raw":
        return f"sub-image {rd.get(entry, 'sub_image')}"
    if kind == "virtual":
        return "virtual image"
    return os.path.splitext(os.path.basename(str(rd.get(entry, "source") or "-")))[0]


def _edges(d):
    rows = [[text(_image(e)), text(",".join(str(v) for v in rd.listing(rd.get(e, "roi")))),
             text(rd.get(e, "axis") or "-"), text(rd.get(e, "direction") or "-"),
             num(rd.number(rd.get(e, "angle_deg")), ".2f"), num(rd.number(rd.get(e, "mtf50_cy_px"))),
             num(rd.number(rd.get(e, "mtf50_expanded_cy_px"))), num(rd.number(rd.get(e, "mtf50_lp_per_mm")), ".2f"),
             num(rd.number(rd.get(e, "mtf50_resolved_distance_m"))), num(rd.number(rd.get(e, "mtf_nyquist")), ".3f")]
            for e in rd.listing(rd.get(d, "edges")) if isinstance(e, dict)]
    if not rows:
        return ""
    body = table("resolution-edges", "Edge regions measured (slanted edge, ISO 12233 e-SFR)",
                 ["image", "region col,row,w,h px", "axis", "direction", "slant deg", "MTF50 cy/px", "U",
                  "MTF50 lp/mm", "GRD m", "MTF Nyquist"], rows)
    return folded(f"Edge regions ({len(rows)})", body, len(rows))


def _axes(d):
    rows = [[text(_image(a)), text(rd.get(a, "axis") or "-"), text(rd.get(a, "direction") or "-"),
             num(rd.get(a, "count"), "d"), num(rd.number(rd.get(a, "mtf50_cy_px"))),
             num(rd.number(rd.get(a, "type_a_u_cy_px"))), num(rd.number(rd.get(a, "type_b_u_cy_px"))),
             num(rd.number(rd.get(a, "mtf50_expanded_cy_px"))), num(rd.number(rd.get(a, "mtf50_lp_per_mm")), ".2f"),
             num(rd.number(rd.get(a, "mtf50_lp_per_mm_expanded")), ".2f"),
             num(rd.number(rd.get(a, "mtf50_resolved_distance_m"))),
             num(rd.number(rd.get(a, "mtf50_resolved_distance_expanded_m")))]
            for a in rd.listing(rd.get(d, "axes")) if isinstance(a, dict)]
    return table("resolution-axes", "MTF50 per image and direction (the edges of an axis combined)",
                 ["image", "axis", "direction", "edges", "MTF50 cy/px", "u_A", "u_B", "U (k=2)", "lp/mm", "U",
                  "GRD m", "U"], rows) if rows else ""


def _loss(d):
    rows = [[text(rd.get(r, "axis") or "-"), text(rd.get(r, "direction") or "-"),
             text(", ".join(str(s) for s in rd.listing(rd.get(r, "sub_images")))),
             num(rd.number(rd.get(r, "raw_mean_mtf50_cy_px"))), num(rd.number(rd.get(r, "virtual_mtf50_cy_px"))),
             num(rd.number(rd.get(r, "loss_cy_px"))), num(rd.number(rd.get(r, "loss_expanded_cy_px"))),
             num(rd.number(rd.get(r, "loss_percent")), ".2f"), num(rd.number(rd.get(r, "loss_expanded_percent")), ".2f")]
            for r in rd.listing(rd.get(d, "resampling_loss")) if isinstance(r, dict)]
    if not rows:
        return note("Resampling loss: not stated (it needs `quality mtf --sub-image` results of the raw sub-images "
                    "and a `--virtual` one of the virtual image).")
    return table("resolution-loss", "Resampling loss: the virtual image's MTF50 against the raw sub-images' mean",
                 ["axis", "direction", "raw sub-images", "raw mean cy/px", "virtual cy/px", "loss cy/px", "U",
                  "loss %", "U %"], rows)


def map_panels(d):
    """{title: [(col, row, mtf50_cy_px)]}: the edges that carry their position in the virtual image
    (`quality mtf --targets`, or `--virtual` with --roi and --image-origin), a panel per direction (or
    axis) and image kind. An edge found in a raw sub-image and measured again in the virtual image
    resampled from it (`--targets --sub-image --virtual-image`: its `resampling` block) is placed
    twice at its one place: its raw MTF50 in the raw sub-images' panel and its virtual MTF50 in the
    virtual image's, so the two panels of a direction compare the same edges."""
    panels = {}
    for e in rd.listing(rd.get(d, "edges")):
        pos = [rd.number(v) for v in rd.listing(rd.get(e, "position_virtual_px"))]
        if len(pos) != 2 or None in pos:
            continue
        direction, axis = rd.get(e, "direction"), rd.get(e, "axis")
        along = f"{direction.replace('_', ' ')} (MTF along {axis})" if direction else f"MTF along {axis}"
        raw = rd.get(e, "image_kind") == "raw"
        virtual = rd.number(rd.get(rd.get(e, "resampling"), "virtual_mtf50_cy_px")) if raw else None
        for which, mtf50 in (("raw sub-images" if raw else "virtual image", rd.number(rd.get(e, "mtf50_cy_px"))),
                             ("virtual image", virtual)):
            if mtf50 is not None:
                panels.setdefault(f"{along}, {which}", []).append((pos[0], pos[1], mtf50))
    return panels


def _map(d):
    """MTF50 across the format (map_panels), one colour scale."""
    fmt_px = [rd.number(v) for v in rd.listing(rd.get(d, "virtual_format_px"))]
    panels = map_panels(d)
    if not panels or len(fmt_px) != 2 or None in fmt_px:
        return ""
    png, facts = plots.mtf_map(sorted(panels.items()), fmt_px[0], fmt_px[1])
    return figure("resolution-map", png, "MTF50 across the format",
                  f"MTF50 of each edge region at its place in the virtual image ({fmt_px[0]:.0f} x {fmt_px[1]:.0f} px), "
                  f"a panel per direction and image (a raw sub-image's edge drawn where the virtual image shows it; "
                  f"the virtual image's panel holds the same edges measured in the virtual image resampled from "
                  f"the sub-images); colour and size from "
                  f"{facts['lo']:.4f} to {facts['hi']:.4f} cycles/px.")


def _pairs(d):
    """Per edge found in a raw sub-image: its MTF50 against the same edge's in the virtual image."""
    rows = []
    for e in rd.listing(rd.get(d, "edges")):
        r = rd.get(e, "resampling") if isinstance(e, dict) else None
        if not isinstance(r, dict):
            continue
        rows.append([text(str(rd.get(e, "sub_image") or "-")), text(str(rd.get(e, "image_id") or "-")),
                     text(str(rd.get(e, "target") or "-")), text(rd.get(e, "direction") or rd.get(e, "axis") or "-"),
                     num(rd.number(rd.get(e, "mtf50_cy_px"))), num(rd.number(rd.get(e, "mtf50_expanded_cy_px"))),
                     num(rd.number(rd.get(r, "virtual_mtf50_cy_px"))),
                     num(rd.number(rd.get(r, "virtual_mtf50_expanded_cy_px"))),
                     num(rd.number(rd.get(r, "loss_percent")), ".2f"), num(rd.number(rd.get(r, "loss_expanded_percent")), ".2f"),
                     num(rd.number(rd.get(r, "predicted_loss_percent")), ".2f"),
                     num(rd.number(rd.get(r, "uniform_phase_loss_percent")), ".2f")])
    if not rows:
        return ""
    body = table("resolution-pairs", "Per edge: raw sub-image against the virtual image resampled from it",
                 ["sub-image", "image", "target", "direction", "raw MTF50 cy/px", "U", "virtual MTF50", "U",
                  "loss %", "U %", "predicted % (mapping shifts)", "predicted % (uniform phase)"], rows)
    return folded(f"Edges in the raw sub-images ({len(rows)})", body, len(rows))


def _subimages(d):
    rows = [[text(str(rd.get(r, "sub_image") or "-")), text(rd.get(r, "axis") or "-"),
             text(rd.get(r, "direction") or "-"), num(rd.get(r, "edges"), "d"),
             num(rd.number(rd.get(r, "raw_mean_mtf50_cy_px"))), num(rd.get(r, "virtual_measured"), "d"),
             num(rd.number(rd.get(r, "virtual_mean_mtf50_cy_px"))), num(rd.number(rd.get(r, "mean_loss_percent")), ".2f"),
             num(rd.number(rd.get(r, "mean_predicted_loss_percent")), ".2f"),
             num(rd.number(rd.get(r, "mean_uniform_phase_loss_percent")), ".2f")]
            for r in rd.listing(rd.get(d, "resampling_per_sub_image")) if isinstance(r, dict)]
    return table("resolution-subimages", "Per raw sub-image: MTF50 and the resampling loss of its edges (means)",
                 ["sub-image", "axis", "direction", "edges", "raw MTF50 cy/px", "in virtual", "virtual MTF50",
                  "loss %", "predicted % (mapping shifts)", "predicted % (uniform phase)"], rows) if rows else ""


def _limits(d):
    rows = []
    for kind, key in (("bar target", "bars"), ("Siemens star", "stars")):
        for i, t in enumerate(x for x in rd.listing(rd.get(d, key)) if isinstance(x, dict)):
            threshold = rd.get(rd.get(t, "options"), "threshold")
            rows.append([text(f"{kind} {i + 1}"), num(rd.number(threshold), ".2f"),
                         num(rd.number(rd.get(t, "limiting_frequency_cy_px"))),
                         num(rd.number(rd.get(t, "limiting_lp_per_mm")), ".2f"),
                         num(rd.number(rd.get(t, "limiting_resolved_distance_m"))),
                         text("yes" if rd.get(t, "limit_in_range") else "no")])
    return table("resolution-limits", "Limiting resolution at the modulation threshold",
                 ["target", "threshold", "limiting cy/px", "lp/mm", "GRD m", "within the target"],
                 rows) if rows else ""


def resolution(doc):
    """The section, or "" when the flight was run without --quality."""
    d = rd.get(doc, "dynamic_image_resolution")
    if not isinstance(d, dict):
        return ""
    sources = ", ".join(esc(os.path.basename(str(s))) for s in rd.listing(rd.get(d, "sources")))
    out = ['<h2 id="resolution">10. Dynamic image resolution</h2>',
           note(f"{esc(rd.get(d, 'method') or 'bar targets / Siemens stars')}; U = k u_c with k = 2; GRD = GSD / "
                f"(2 f), one bar width; from the results of `aerocal quality` ({sources}), as in the certificate.")]
    out += [_axes(d), _loss(d), _subimages(d), _map(d), _limits(d), _pairs(d), _edges(d)]
    return "".join(out)
