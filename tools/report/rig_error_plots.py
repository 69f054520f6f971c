"""PNG plots of `aerocal rig error-analysis`: the Monte-Carlo histograms (ex, ey, radial) and the
grid's bound map, from the CSV files that result.json names (monte_carlo.histogram_csv,
grid.bound_map_csv), written to the PNG names it gives (histogram_png, bound_map_png) beside it.

    python3 tools/report/rig_error_plots.py RESULT.json

matplotlib (Agg) and numpy from Debian, as tools/report/aerocal_report.py. Exit 0 on success, 2 with
`error: ...` when the result is not a rig error analysis, 1 when matplotlib is missing. Each PNG is
written to a temporary file and renamed; no timestamp or software tag is stored, so reruns give the
same bytes.
"""
import csv
import json
import os
import sys

sys.dont_write_bytecode = True  # keep the source tree free of __pycache__


# ResultSchemaVersion("rig_error_analysis") of calib/core/result_file.h: the version this reader understands.
SCHEMA_VERSION = 2


def _fail(message, code):
    sys.stderr.write(f"error: {message}\n")
    sys.exit(code)


def _save(fig, path):
    tmp = path + ".tmp"
    fig.savefig(tmp, format="png", dpi=100, bbox_inches="tight", metadata={"Software": None})
    os.replace(tmp, path)


def _histograms(plt, csv_path, png_path, doc):
    rows = {}
    with open(csv_path, newline="") as f:
        for r in csv.DictReader(f):
            rows.setdefault(r["quantity"], []).append(
                (float(r["bin_low_px"]), float(r["bin_high_px"]), int(r["count"])))
    mc, linear = doc["monte_carlo"], doc["linear"]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), constrained_layout=True)
    titles = {"ex": "ex (px)", "ey": "ey (px)", "radial": "|e| (px)"}
    for ax, (quantity, bound) in zip(axes, [("ex", mc["bound_px"][0]), ("ey", mc["bound_px"][1]),
                                            ("radial", mc["bound_radial_px"])]):
        bins = rows.get(quantity, [])
        ax.bar([lo for lo, _, _ in bins], [n for _, _, n in bins],
               width=[hi - lo for lo, hi, _ in bins], align="edge", color="#4878a8")
        for sign in ([1] if quantity == "radial" else [-1, 1]):
            ax.axvline(sign * bound, color="#c03030", linestyle="--", linewidth=1)
        ax.set_xlabel(titles[quantity])
        ax.set_ylabel("samples")
    axes[0].set_title(f"Monte-Carlo n = {mc['n']}, seed {mc['seed']}; dashed: 99.75 % bound; "
                      f"linear sigma {linear['sigma_px'][0]:.3f} / {linear['sigma_px'][1]:.3f} px",
                      loc="left", fontsize=9)
    _save(fig, png_path)
    plt.close(fig)


def _bound_map(plt, csv_path, png_path):
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    cols = [float(r["virtual_col"]) for r in rows]
    rws = [float(r["virtual_row"]) for r in rows]
    bound = [float(r["linear_bound_radial_px"]) for r in rows]
    fig, ax = plt.subplots(figsize=(6, 5))
    sc = ax.scatter(cols, rws, c=bound, s=120, marker="s", cmap="viridis")
    ax.invert_yaxis()
    ax.set_aspect("equal")
    ax.set_xlabel("virtual col (px)")
    ax.set_ylabel("virtual row (px)")
    fig.colorbar(sc, ax=ax, label="linear 99.75 % radial bound (px)")
    _save(fig, png_path)
    plt.close(fig)


def main(argv):
    if len(argv) != 2:
        _fail("usage: rig_error_plots.py RESULT.json", 2)
    try:
        with open(argv[1]) as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        _fail(f"{argv[1]}: {e}", 2)
    if not isinstance(doc, dict) or doc.get("kind") != "rig_error_analysis":
        _fail(f"{argv[1]}: not a rig error analysis (kind must be 'rig_error_analysis')", 2)
    if doc.get("schema_version") != SCHEMA_VERSION or isinstance(doc.get("schema_version"), bool):
        _fail(f"{argv[1]}: schema_version is {json.dumps(doc.get('schema_version'))}, expected {SCHEMA_VERSION} "
              f"(kind \"rig_error_analysis\")", 2)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        if "text.parse_math" in matplotlib.rcParams:  # ids are text, never mathtext (issue 37)
            matplotlib.rcParams["text.parse_math"] = False
    except ImportError:
        # A python3 earlier in PATH (pyenv, virtualenv) may lack Debian's matplotlib: use Debian's.
        debian = "/usr/bin/python3"
        if os.path.exists(debian) and os.path.realpath(sys.executable) != os.path.realpath(debian):
            os.execv(debian, [debian, os.path.abspath(__file__)] + argv[1:])
        _fail("matplotlib is missing (install the Debian package python3-matplotlib)", 1)
    folder = os.path.dirname(os.path.abspath(argv[1]))
    mc = doc.get("monte_carlo") or {}
    if mc.get("histogram_csv") and mc.get("histogram_png"):
        _histograms(plt, os.path.join(folder, mc["histogram_csv"]),
                    os.path.join(folder, mc["histogram_png"]), doc)
    grid = doc.get("grid") or {}
    if grid.get("bound_map_csv") and grid.get("bound_map_png"):
        _bound_map(plt, os.path.join(folder, grid["bound_map_csv"]),
                   os.path.join(folder, grid["bound_map_png"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
