#!/usr/bin/python3
"""Writes the report test fixture result.json (see README.md beside this file).

Usage: make_fixture.py STITCH_JSON SIMULATED_FOLDER OUT_JSON

The "stitching" section is the real output of `aerocal stitch` (trimmed of per-observation detail);
the "adjustments" section follows the result keys of FORMATS.md with figures synthesised from the
simulation truth (distortion left in the residuals of the conventional run, noise elsewhere), so the
renderer sees realistic magnitudes and patterns.
"""
import csv
import json
import math
import os
import random
import sys

import numpy as np

NAMES = ["c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2"]


def read_yaml_interior(path):
    values, inside = {}, False
    for line in open(path):
        if line.startswith("interior:"):
            inside = True
            continue
        if inside and line.startswith("  ") and ":" in line:
            k, v = line.strip().split(":")
            values[k.strip()] = float(v)
        elif inside:
            break
    return values


def correction(p, x, y):  # CONVENTIONS.md, 10-parameter model, mm
    xb, yb = x - p["x0"], y - p["y0"]
    r2 = xb * xb + yb * yb
    radial = p["K1"] * r2 + p["K2"] * r2**2 + p["K3"] * r2**3
    dx = xb * radial + p["P1"] * (r2 + 2 * xb * xb) + 2 * p["P2"] * xb * yb + p["B1"] * xb + p["B2"] * yb
    dy = yb * radial + 2 * p["P1"] * xb * yb + p["P2"] * (r2 + 2 * yb * yb)
    return dx, dy


def stats(diffs):
    d = np.array(diffs)
    rmse = np.sqrt((d**2).mean(axis=0))
    return {"n": len(d), "rmse_m": rmse.round(4).tolist(), "mean_m": d.mean(axis=0).round(4).tolist(),
            "max_abs_m": np.abs(d).max(axis=0).round(4).tolist(),
            "planimetric_rmse_m": round(float(np.hypot(rmse[0], rmse[1])), 4),
            "spatial_rmse_m": round(float(np.linalg.norm(rmse)), 4)}


def main():
    stitch_path, sim, out = sys.argv[1:4]
    rng = random.Random(7)
    stitch = json.load(open(stitch_path))
    for f in stitch["frames"]:
        f.pop("residuals", None)
        f.pop("diagnostics", None)
        for s in f["subimages"]:
            s.pop("corners", None)
    nominal = read_yaml_interior(os.path.join(sim, "camera_nominal.yaml"))
    truth = read_yaml_interior(os.path.join(sim, "camera_truth.yaml"))
    W, H, p = 14000, 12000, 0.009
    frames = {f["frame"] for f in stitch["frames"]}
    obs = [r for r in csv.DictReader(open(os.path.join(sim, "observations.csv"))) if r["image"] in frames]
    points = list(csv.DictReader(open(os.path.join(sim, "points.csv"))))

    # Distortion the nominal camera does not model, minus its best affine fit (absorbed by the
    # exterior orientations), in px: what the conventional run leaves in its residuals.
    xy = np.array([[(float(o["col"]) - (W - 1) / 2) * p, -(float(o["row"]) - (H - 1) / 2) * p] for o in obs])
    d = np.array([np.subtract(correction(truth, x, y), correction(nominal, x, y)) for x, y in xy]) / p
    A = np.c_[np.ones(len(xy)), xy]
    systematic = d - A @ np.linalg.lstsq(A, d, rcond=None)[0]

    sigmas = {"self_calibration": dict(zip(NAMES, [0.0042, 0.0031, 0.0029, 2.1e-9, 4.4e-13, 3.2e-17, 2.9e-8, 3.1e-8, 2.2e-6, 2.4e-6]))}
    sigmas["joint"] = {k: v * 0.9 for k, v in sigmas["self_calibration"].items()}
    noise_px = {"conventional": 0.16, "self_calibration": 0.15, "joint": 0.145}
    plan = {"conventional": 0.11, "self_calibration": 0.055, "joint": 0.05}
    height = {"conventional": 0.21, "self_calibration": 0.09, "joint": 0.085}
    sigma0_px = {"conventional": 0.291, "self_calibration": 0.152, "joint": 0.147}
    redundancy = {"conventional": 3891, "self_calibration": 3881, "joint": 74210}
    adjustments = []
    for name in ["conventional", "self_calibration", "joint"]:
        a = {"name": name, "kind": "adjust", "sigma0": round(sigma0_px[name] / 0.2, 4),
             "sigma0_px": sigma0_px[name], "sigma0_um": round(sigma0_px[name] * 9, 3),
             "redundancy": redundancy[name], "iterations": {"conventional": 5, "self_calibration": 7, "joint": 9}[name],
             "converged": True, "self_calibration": [] if name == "conventional" else NAMES[:8]}
        est = dict(nominal)
        if name != "conventional":
            est = {k: truth[k] + rng.gauss(0, sigmas[name][k]) for k in NAMES}
            est["B1"], est["B2"] = nominal["B1"], nominal["B2"]
        a["cameras"] = [{"id": "cam1", "initial": nominal, "estimated": est,
                         "sigma": {k: sigmas[name][k] for k in NAMES[:8]} if name != "conventional" else {},
                         "free": a["self_calibration"]}]
        check, control = [], []
        for pt in points:
            if pt["role"] not in ("check", "control"):
                continue
            X, Y, Z = float(pt["X"]), float(pt["Y"]), float(pt["Z"])
            if name == "conventional":  # radial scale error of the block grows outwards; Z bias from c
                dXYZ = [X * 1.2e-5 + rng.gauss(0, plan[name]), Y * 1.2e-5 + rng.gauss(0, plan[name]),
                        0.12 + 0.25 * (X / 8000) ** 2 + rng.gauss(0, height[name])]
            else:
                dXYZ = [rng.gauss(0, plan[name]), rng.gauss(0, plan[name]), rng.gauss(0.01, height[name])]
            if pt["role"] == "control":
                dXYZ = [v * 0.3 for v in dXYZ]
            row = {"point": pt["point"], "surveyed": [X, Y, Z],
                   "adjusted": [round(X + dXYZ[0], 4), round(Y + dXYZ[1], 4), round(Z + dXYZ[2], 4)],
                   "difference_m": [round(v, 4) for v in dXYZ], "rays": rng.randint(2, 9)}
            if pt["role"] == "check":
                check.append(row)
            elif pt["role"] == "control":
                control.append(row)
        a["control"] = dict(stats([r["difference_m"] for r in control]), points=control)
        a["check"] = dict(stats([r["difference_m"] for r in check]), points=check)
        a["residuals"] = []
        for o, s in zip(obs, systematic):
            v = (s if name == "conventional" else s * 0.03) + [rng.gauss(0, noise_px[name]) for _ in range(2)]
            a["residuals"].append({"image": o["image"], "point": o["point"], "col": round(float(o["col"]), 1),
                                   "row": round(float(o["row"]), 1), "v_col_px": round(v[0], 3),
                                   "v_row_px": round(-v[1], 3)})
        a["rejected"] = [{"image": "0003", "point": "T211", "residual_px": 2.41, "w": 5.2}] if name != "joint" else []
        a["determinability"] = {"determinable": True, "message": "", "undetermined": [], "warnings": [],
                                "high_correlations": []}
        if name == "joint":
            a["mapping_scope"] = "per-flight"
            a["datum"] = "base sub-images III, IV keep the camera file's mapping"
            a["subimages"] = []
            for s in stitch["subimages"]:
                sig = [v * 0.6 for v in s["sigma"]]
                a["subimages"].append({"id": s["id"], "camera": "cam1", "model": s["model"],
                                       "param_names": s.get("param_names"), "base": s["base"],
                                       "initial": s["params"],
                                       "params": [v + rng.gauss(0, e) for v, e in zip(s["params"], sig)],
                                       "sigma": sig})
            a["stitching_per_exposure"] = [
                {"image": f["frame"], "n_observations": f["n_observations"], "sigma0_before_px": f["sigma0_px"],
                 "sigma0_after_px": round(f["sigma0_px"] * rng.uniform(0.97, 1.02), 4)} for f in stitch["frames"]]
            a["mapping_interior_correlations"] = []
        adjustments.append(a)

    doc = {"kind": "flight", "schema_version": 2, "aerocal_version": "0.1.0", "camera": "data/camera_nominal.yaml", "data": "data",
           "camera_format": {"width_px": W, "height_px": H, "pixel_size_mm": p},
           "stitching": stitch, "adjustments": adjustments}
    # The project facts of the flight result (tools/report/report_facts.py), as the writer states them.
    doc.update({"camera_name": "6-CCD camera, 2 x 3 sub-images (simulated)", "frame": "projected frame, used as given (simulated block)", "camera_written_from": {"adjustment": "joint", "reason": "the joint stitching + triangulation adjustment (interior and the sub-image mappings refined together)"}, "inputs": [{"role": "project", "path": "data/project.yaml", "bytes": 231, "sha256": "0000000000000000000000000000000000000000000000000000000000000000"}]})
    with open(out, "w") as f:
        json.dump(doc, f, separators=(",", ":"))


if __name__ == "__main__":
    main()
