#!/usr/bin/env python3
"""Calibrate a flight's camera and plot the residual field of its images.

    python3 calibrate_flight.py PROJECT [--self-calibration auto] [--plot residuals.png]

PROJECT is a project YAML (or its folder) as `aerocal adjust --project` reads it. The script
adjusts the block with self-calibration, prints the camera parameters with their sigmas and the
check-point RMSE, and draws the image residuals averaged in cells of the measured area: the
systematic part that remains is what the camera model did not absorb. Exit 3 when the adjustment
is not valid (as `aerocal adjust`), 2 on bad input.
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import aerocal


def cell_means(pixels, residuals, cells):
    """Mean residual per cell of a cells x cells grid over the pixels' extent."""
    low, high = pixels.min(axis=0), pixels.max(axis=0)
    index = np.minimum(((pixels - low) / (high - low + 1e-9) * cells).astype(int), cells - 1)
    centres, means = [], []
    for i in range(cells):
        for k in range(cells):
            inside = (index[:, 0] == i) & (index[:, 1] == k)
            if inside.sum() >= 3:  # a mean of fewer rays says little
                centres.append(pixels[inside].mean(axis=0))
                means.append(residuals[inside].mean(axis=0))
    return np.array(centres), np.array(means)


def plot_residual_field(result, path, cells):
    table = result.residuals
    used = table["used"]
    pixels, residuals = table["measured_px"][used], table["residual_px"][used]
    centres, means = cell_means(pixels, residuals, cells)
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.quiver(pixels[:, 0], pixels[:, 1], residuals[:, 0], -residuals[:, 1], color="0.75",
              angles="xy", scale_units="xy", scale=1.0 / 200.0, width=0.002)
    ax.quiver(centres[:, 0], centres[:, 1], means[:, 0], -means[:, 1], color="C3", angles="xy",
              scale_units="xy", scale=1.0 / 2000.0, width=0.004)
    ax.set_xlabel("column (px)")
    ax.set_ylabel("row (px)")
    ax.invert_yaxis()
    ax.set_aspect("equal")
    ax.set_title(f"image residuals x200 (grey), cell means x2000 (red); "
                 f"sigma0 {result.sigma0:.3f}")
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("project")
    parser.add_argument("--self-calibration", default="auto")
    parser.add_argument("--plot", default="residuals.png")
    parser.add_argument("--cells", type=int, default=6)
    args = parser.parse_args()
    try:
        block = aerocal.Block.read(args.project)
        result = aerocal.adjust(block, self_calibration=args.self_calibration,
                                progress=lambda done, total: print(
                                    f"\rstage {done}/{total}", end="", file=sys.stderr))
    except ValueError as error:  # InputError / ConfigError: FILE:LINE or the option
        print(f"\n{error}", file=sys.stderr)
        return 2
    print(file=sys.stderr)
    print(f"sigma0 {result.sigma0!r}")
    for camera in result.cameras:
        for name, value in camera.estimated.items():
            sigma = camera.sigma[name]
            print(f"camera {camera.id} {name} {value!r} " +
                  (f"+- {sigma!r}" if sigma is not None else "(held)"))
    print("check RMSE X Y Z (m): " + " ".join(repr(float(v)) for v in result.check_rmse_m))
    plot_residual_field(result, args.plot, args.cells)
    print(f"residual field: {args.plot}")
    if not result.valid:
        print("NOT VALID: " + "; ".join(result.invalid_reasons), file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
