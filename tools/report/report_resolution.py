"""Section 10 of the report: the dynamic image resolution (`aerocal flight --quality Q.json`).

Every number is the one C++ wrote into result.json's `dynamic_image_resolution`
(tools/dynamic_resolution.h, the certificate's section): the edge regions measured, MTF50 with U
(k = 2) per image and axis, the resampling loss (virtual image against the raw sub-images' mean)
and the limiting resolution of bar targets and Siemens stars. Nothing is recomputed here.
"""
import os

import report_data as rd
from report_html import esc, note, num, table, text
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
    out += [_axes(d), _loss(d), _limits(d), _edges(d)]
    return "".join(out)
