#!/usr/bin/env bash
# The dynamic image resolution of a simulated multi-CCD flight (issue 36's flight example):
#
#   examples/flight_resolution.sh [OUT] [PSF_SIGMA_PX]
#
# 1. `aerocal simulate --edge-targets` lays out square edge targets on the ground and renders, for
#    every exposure that sees an edge inside one CCD, a patch of the raw sub-image through the true
#    camera and a Gaussian PSF, and the virtual image's patch resampled from it (bilinear, the
#    production resampler): OUT/data/edge_targets/raw_<CCD>.tif, virtual.tif, patches.csv.
# 2. `aerocal quality mtf` measures every edge of each mosaic (the regions from patches.csv):
#    OUT/quality/raw_<CCD>.json per CCD and OUT/quality/virtual.json, MTF50 per edge and per axis
#    (along / across track) with U (k = 2).
# 3. `aerocal flight --certificate --quality ...` calibrates the flight and writes result.json,
#    report.html and the certificate with their "dynamic image resolution" section
#    (OUT/flight/, OUT/flight/certificate/), the resampling loss per axis stated with its U.
# The script prints the MTF50 per axis of the raw CCDs and of the virtual image: the virtual one is
# lower by bilinear interpolation's loss at the CCD mappings' sub-pixel shifts
# (stitch/quality/README.md "Resampling"). AEROCAL names the executable (default: aerocal).
set -euo pipefail
AEROCAL=${AEROCAL:-aerocal}
OUT=${1:-flight_resolution}
SIGMA=${2:-1.0}
mkdir -p "$OUT/quality"
"$AEROCAL" simulate --out "$OUT/data" --seed 3 --edge-targets --psf-sigma-px "$SIGMA"
patches="$OUT/data/edge_targets/patches.csv"
# The regions of one mosaic file (columns 5-9: raw file and region, 10-14: virtual) as --roi options.
rois() {
  awk -F, -v file="$1" 'NR > 2 && $5 == file { printf " --roi %s,%s,%s,%s", $6, $7, $8, $9 }
                        NR > 2 && $10 == file { printf " --roi %s,%s,%s,%s", $11, $12, $13, $14 }' \
    "$patches"
}
results=()
for image in "$OUT"/data/edge_targets/*.tif; do
  name=$(basename "$image" .tif)
  # raw_<CCD>.tif is that CCD's raw sub-image, virtual.tif the virtual image: the resampling loss
  # compares them.
  if [ "$name" = virtual ]; then which=(--virtual); else which=(--sub-image "${name#raw_}"); fi
  # shellcheck disable=SC2046  # the --roi options are meant to split
  "$AEROCAL" --quiet quality mtf --image "$image" $(rois "$(basename "$image")") "${which[@]}" \
    --flight-axis x --pixel-size-mm 0.009 --out "$OUT/quality/$name.json" >/dev/null
  results+=(--quality "$OUT/quality/$name.json")
done
"$AEROCAL" flight --camera "$OUT/data/camera_nominal.yaml" --data "$OUT/data" --base III,IV \
  --out "$OUT/flight" --certificate "${results[@]}"
python3 - "$OUT/quality" "$OUT/flight/result.json" <<'PY'
import json, pathlib, sys
for path in sorted(pathlib.Path(sys.argv[1]).glob("*.json")):
    doc = json.loads(path.read_text())
    for axis, a in sorted(doc["axes"].items()):
        print(f"{path.stem:8s} {axis} ({a['direction']:12s}) {a['count']:2d} edges: MTF50 "
              f"{a['mtf50_cy_px']:.4f} +- {a['mtf50_expanded_cy_px']:.4f} cycles/px (k = 2)")
# The resampling loss as result.json (and report.html, the certificate) state it.
for r in json.loads(pathlib.Path(sys.argv[2]).read_text())["dynamic_image_resolution"]["resampling_loss"]:
    print(f"loss {r['axis']} ({r['direction']:12s}): raw mean {r['raw_mean_mtf50_cy_px']:.4f}, virtual "
          f"{r['virtual_mtf50_cy_px']:.4f}: {r['loss_cy_px']:.4f} +- {r['loss_expanded_cy_px']:.4f} cycles/px, "
          f"{r['loss_percent']:.2f} +- {r['loss_expanded_percent']:.2f} % (k = 2)")
PY
