"""The report's figures, drawn with matplotlib (Agg, no display) and returned as base64 PNG.

Geometry follows CONVENTIONS.md: image plots are in photo coordinates (x right, y up, mm, origin
at the format centre), so a vector pattern reads the way the 10-parameter model is written.
"""
import base64
import io
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

# Ids from the user's files (exposures, cameras, sub-images) are drawn as text, never as mathtext:
# an id with `$...$` crashed the renderer (issue 37). matplotlib < 3.6 lacks the switch.
try:
    matplotlib.rcParams["text.parse_math"] = False
except KeyError:  # pragma: no cover
    pass
import numpy as np  # noqa: E402

DPI = 100
GRID_THRESHOLD = 300  # above this many residuals per panel, vectors are averaged per cell
GRID_COLUMNS = 10     # cells across the format; rows follow the format's aspect ratio


def _png(fig):
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI, bbox_inches="tight", metadata={"Software": None})
    plt.close(fig)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def nice(x):
    """The 1-2-5 number nearest below x (x > 0)."""
    e = math.floor(math.log10(x))
    for m in (5, 2, 1):
        if m * 10**e <= x:
            return m * 10**e
    return 10**e


def _panels(n, columns, height_in):
    cols = min(columns, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(11.5, height_in * rows), squeeze=False, layout="constrained")
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


# ---- stitching ------------------------------------------------------------------------------

def sigma0_per_exposure(series, chosen, flagged, mean_line):
    """series: {model: [sigma0_px or None per frame]} in frame order; chosen: [(frame, model,
    sigma0_px)]; flagged: set of frames; mean_line: (label, value) or None."""
    frames = [f for f, _, _ in chosen]
    x = np.arange(len(frames))
    fig, ax = plt.subplots(figsize=(11.5, 4.2), layout="constrained")
    for model, values in series.items():
        y = np.array([np.nan if v is None else v for v in values], dtype=float)
        ax.plot(x, y, marker=".", linewidth=1, label=f"{model}")
    cy = np.array([np.nan if v is None else v for _, _, v in chosen], dtype=float)
    ax.plot(x, cy, linestyle="none", marker="o", markersize=9, markerfacecolor="none",
            markeredgecolor="black", label="chosen model of the exposure")
    marks = [k for k, f in enumerate(frames) if f in flagged]
    if marks:
        ax.plot(x[marks], cy[marks], linestyle="none", marker="x", markersize=11, color="red",
                markeredgewidth=2, label="flagged by the stability test")
    if mean_line:
        ax.axhline(mean_line[1], color="grey", linestyle="--", linewidth=1, label=mean_line[0])
    step = max(1, len(frames) // 25)
    ax.set_xticks(x[::step])
    ax.set_xticklabels(frames[::step], rotation=45 if len(frames) > 12 else 0, fontsize=8)
    ax.set_xlabel("exposure (frame)")
    ax.set_ylabel("sigma0 [px]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.2))
    ax.set_title("Stitching sigma0 per exposure")
    return _png(fig)


# ---- residual vectors over the image format --------------------------------------------------

def _grid_means(xy, v, half_w, half_h):
    """Mean vector per cell of a GRID_COLUMNS x rows grid over the format."""
    nx = GRID_COLUMNS
    ny = max(1, round(nx * half_h / half_w))
    ix = np.clip(((xy[:, 0] + half_w) / (2 * half_w) * nx).astype(int), 0, nx - 1)
    iy = np.clip(((xy[:, 1] + half_h) / (2 * half_h) * ny).astype(int), 0, ny - 1)
    centres, means, counts = [], [], []
    for i in range(nx):
        for j in range(ny):
            mask = (ix == i) & (iy == j)
            if mask.any():
                centres.append([-half_w + (i + 0.5) * 2 * half_w / nx, -half_h + (j + 0.5) * 2 * half_h / ny])
                means.append(v[mask].mean(axis=0))
                counts.append(int(mask.sum()))
    return np.array(centres), np.array(means), np.array(counts), (nx, ny)


def residual_vectors(panels, width_px, height_px, pixel_mm):
    """panels: [(title, [(col, row, v_col_px, v_row_px)])]. One scale for all panels, so the
    panels compare directly. Returns (png, caption facts dict)."""
    half_w, half_h = (width_px - 1) / 2 * pixel_mm, (height_px - 1) / 2 * pixel_mm
    prepared, longest, gridded = [], 0.0, None
    for title, rows in panels:
        a = np.array(rows, dtype=float)
        xy = np.c_[(a[:, 0] - (width_px - 1) / 2) * pixel_mm, -(a[:, 1] - (height_px - 1) / 2) * pixel_mm]
        v = np.c_[a[:, 2], -a[:, 3]]  # photo frame: y up, so the row component changes sign
        rms = float(np.sqrt((v**2).sum(axis=1).mean()))
        if len(a) > GRID_THRESHOLD:
            xy, v, counts, gridded = _grid_means(xy, v, half_w, half_h)
        prepared.append((title, xy, v, len(a), rms))
        longest = max(longest, float(np.hypot(v[:, 0], v[:, 1]).max()))
    # Exaggeration: the longest drawn vector spans about one grid cell (or 1/12 of the width).
    target_mm = 2 * half_w / (GRID_COLUMNS if gridded else 12)
    exaggeration = nice(target_mm / (max(longest, 1e-9) * pixel_mm))
    key_px = nice(max(longest, 1e-9) * 0.6)
    fig, axes = _panels(len(prepared), 2, 4.6)
    for ax, (title, xy, v, n, rms) in zip(axes, prepared):
        ax.add_patch(plt.Rectangle((-half_w, -half_h), 2 * half_w, 2 * half_h, fill=False, color="grey"))
        scale_mm_per_px = exaggeration * pixel_mm
        q = ax.quiver(xy[:, 0], xy[:, 1], v[:, 0] * scale_mm_per_px, v[:, 1] * scale_mm_per_px,
                      angles="xy", scale_units="xy", scale=1, color="#1f4e9a", width=0.004)
        ax.quiverkey(q, 0.80, 1.03, key_px * scale_mm_per_px, f"{key_px:g} px", labelpos="E",
                     coordinates="axes", fontproperties={"size": 8})
        ax.set_aspect("equal")
        ax.set_xlim(-half_w * 1.05, half_w * 1.05)
        ax.set_ylim(-half_h * 1.05, half_h * 1.05)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(f"{title}\n{n} residuals, RMS {rms:.3f} px", fontsize=9, loc="left")
        ax.tick_params(labelsize=8)
    facts = {"exaggeration": exaggeration, "key_px": key_px, "grid": gridded}
    return _png(fig), facts


# ---- distortion curves ----------------------------------------------------------------------

def radial_um(p, r_mm):
    return 1000.0 * r_mm * (p.get("K1", 0) * r_mm**2 + p.get("K2", 0) * r_mm**4 + p.get("K3", 0) * r_mm**6)


def decentring_um(p, r_mm):
    return 1000.0 * math.hypot(p.get("P1", 0), p.get("P2", 0)) * r_mm**2


def distortion_curves(camera_id, curves, half_w_mm, half_h_mm):
    """curves: [(label, interior dict, is_initial)] for one camera; r from 0 to the half-diagonal."""
    r_max = math.hypot(half_w_mm, half_h_mm)
    r = np.linspace(0.0, r_max, 200)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11.5, 3.8), layout="constrained")
    for label, p, initial in curves:
        style = {"color": "grey", "linestyle": "--"} if initial else {}
        left.plot(r, radial_um(p, r), label=label, **style)
        right.plot(r, decentring_um(p, r), label=label, **style)
    for ax, what in ((left, "radial dr(r) = r (K1 r^2 + K2 r^4 + K3 r^6)"),
                     (right, "decentring P(r) = sqrt(P1^2 + P2^2) r^2")):
        for edge, name in ((half_h_mm, "half height"), (half_w_mm, "half width")):
            ax.axvline(edge, color="#999999", linewidth=0.8, linestyle=":")
            ax.text(edge, 0.02, f" {name}", rotation=90, fontsize=7, color="#666666",
                    transform=ax.get_xaxis_transform(), va="bottom")
        ax.axhline(0, color="black", linewidth=0.6)
        ax.set_xlim(0, r_max)
        ax.set_xlabel("radial distance r [mm]")
        ax.set_ylabel("distortion [um]")
        ax.set_title(f"camera {camera_id}: {what}", fontsize=9, loc="left")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        ax.tick_params(labelsize=8)
    return _png(fig)


# ---- check-point error map ------------------------------------------------------------------

def check_point_map(panels):
    """panels: [(title, check [(id, X, Y, Z, dX, dY, dZ)], control [...])]. One vector scale and
    one colour scale for all panels. Returns (png, facts dict)."""
    all_points = [p for _, check, control in panels for p in check + control]
    xs = np.array([p[1] for p in all_points])
    ys = np.array([p[2] for p in all_points])
    span = max(xs.max() - xs.min(), ys.max() - ys.min(), 1.0)
    # Scale from the largest planimetric RMSE of the panels: such an error is drawn 1/60 of the block.
    plan = max(max(math.sqrt(np.mean([p[4] ** 2 + p[5] ** 2 for p in check])) for _, check, _ in panels), 1e-9)
    z_lim = max(max(abs(p[6]) for _, check, _ in panels for p in check), 1e-9)
    exaggeration = nice(span / 60 / plan)
    key_m = nice(plan * 1.5)
    fig, axes = _panels(len(panels), 1, 4.4)
    scatter = None
    for ax, (title, check, control) in zip(axes, panels):
        c = np.array([p[1:] for p in check], dtype=float)
        scatter = ax.scatter(c[:, 0], c[:, 1], c=c[:, 5], cmap="RdBu_r", vmin=-z_lim, vmax=z_lim, s=20,
                             edgecolors="#444444", linewidths=0.3, zorder=2)
        q = ax.quiver(c[:, 0], c[:, 1], c[:, 3] * exaggeration, c[:, 4] * exaggeration, angles="xy",
                      scale_units="xy", scale=1, color="black", width=0.0016, headwidth=4,
                      headlength=4, headaxislength=3.5, zorder=3)
        ax.quiverkey(q, 0.78, 1.03, key_m * exaggeration, f"{key_m:g} m", labelpos="E",
                     coordinates="axes", fontproperties={"size": 8})
        if control:
            g = np.array([p[1:3] for p in control], dtype=float)
            ax.plot(g[:, 0], g[:, 1], linestyle="none", marker="^", markersize=8, color="#e07b00",
                    markeredgecolor="black", label="control", zorder=4)
            ax.legend(fontsize=7, loc="lower left")
        rmse = np.sqrt((c[:, 3:6] ** 2).mean(axis=0))
        ax.set_title(f"{title}\n{len(c)} check points, RMSE XY {math.hypot(rmse[0], rmse[1]):.3f} m, "
                     f"Z {rmse[2]:.3f} m", fontsize=9, loc="left")
        ax.set_aspect("equal")
        ax.margins(0.06)
        ax.set_xlabel("X [m]")
        ax.set_ylabel("Y [m]")
        ax.tick_params(labelsize=7)
        ax.ticklabel_format(useOffset=False, style="plain")
    fig.colorbar(scatter, ax=axes, shrink=0.9, aspect=40, label="Z error dZ [m]")
    return _png(fig), {"exaggeration": exaggeration, "key_m": key_m, "z_lim": z_lim}


# ---- MTF50 across the format (dynamic image resolution) -------------------------------------

def mtf_map(panels, width_px, height_px):
    """panels: [(title, [(col, row, mtf50_cy_px)])], positions in the virtual image's pixels. One
    colour scale for all panels; the marker's area grows with MTF50 too, so the map reads without
    colour. Returns (png, facts dict)."""
    values = [p[2] for _, points in panels for p in points]
    lo, hi = min(values), max(values)
    if hi - lo < 1e-9:
        lo, hi = lo - 0.005, hi + 0.005
    fig, axes = _panels(len(panels), 2, 4.6)
    scatter = None
    for ax, (title, points) in zip(axes, panels):
        ax.add_patch(plt.Rectangle((0, 0), width_px, height_px, fill=False, color="grey"))
        p = np.array(points, dtype=float).reshape(-1, 3)
        scatter = ax.scatter(p[:, 0], p[:, 1], c=p[:, 2], cmap="viridis", vmin=lo, vmax=hi,
                             s=20 + 100 * (p[:, 2] - lo) / (hi - lo), edgecolors="#333333", linewidths=0.4)
        ax.set_aspect("equal")
        ax.set_xlim(-0.02 * width_px, 1.02 * width_px)
        ax.set_ylim(1.02 * height_px, -0.02 * height_px)  # image rows grow downwards
        ax.set_xlabel("column [px]")
        ax.set_ylabel("row [px]")
        ax.set_title(f"{title}\n{len(points)} edge regions", fontsize=9, loc="left")
        ax.tick_params(labelsize=7)
    fig.colorbar(scatter, ax=axes, shrink=0.9, aspect=40, label="MTF50 [cycles/px]")
    return _png(fig), {"lo": lo, "hi": hi}
