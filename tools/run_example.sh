#!/usr/bin/env bash
# The main job on the bundled example: simulate the example flight of the 2x3-CCD camera
# (configs/example_flight.yaml documents its parameters) and run the calibration workflow on it.
# Results go to out/example/.
set -euo pipefail
cd "$(dirname "$0")/.."
aerocal=build/tools/aerocal
rm -rf out/example/data
$aerocal simulate --out out/example/data --seed 1
if $aerocal flight --help >/dev/null 2>&1; then
  $aerocal flight --camera out/example/data/camera_nominal.yaml --data out/example/data --out out/example/report
  echo "report: out/example/report/report.html"
else
  $aerocal stitch --camera out/example/data/camera_nominal.yaml --obs out/example/data/stitch_obs.csv \
    --model auto --base III,IV --out out/example/stitch.json
  $aerocal adjust --project out/example/data/project.yaml --self-calibration all --compare \
    --write-camera out/example/camera_calibrated.yaml --out out/example/adjust.json
fi
