#!/usr/bin/env bash
# The main job on the bundled example: simulate the example flight of the 2x3-CCD camera
# (seeded, so always the same data) and run the calibration workflow on it: stitching with model
# choice and flight stability, conventional / self-calibrating / joint adjustment, report.
# Results: out/example/report/ (result.json, report.html, camera_calibrated.yaml).
set -euo pipefail
cd "$(dirname "$0")/.."
aerocal=build/tools/aerocal
$aerocal --mkdir simulate --out out/example/data --seed 1 --gnss-sigma-m 0.05
$aerocal flight --camera out/example/data/camera_nominal.yaml --data out/example/data --base III,IV \
  --out out/example/report
