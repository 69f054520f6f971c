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
# 3. `aerocal flight --no-report` adjusts the flight (OUT/adjusted/result.json): the exposures'
#    orientation and the stitching's mappings that step 4 needs.
# 4. `aerocal quality mtf --targets --sub-image --mapping --virtual-image` finds the first patch of
#    every CCD and axis from its target's ground ends (projected with the adjusted camera and
#    exposure, then through the mappings into the CCD), measures it in the raw sub-image and in the
#    virtual image resampled from it: OUT/quality/targets_<TARGET>_<IMAGE>.json, each edge with its
#    place in the virtual image and its resampling block (measured and predicted loss).
# 5. `aerocal flight --certificate --quality ...` (all results of steps 2 and 4) writes result.json,
#    report.html and the certificate with their "dynamic image resolution" section
#    (OUT/flight/, OUT/flight/certificate/): the resampling loss per axis with its U, the MTF50 map
#    across the format (figure resolution-map) and the per-sub-image and per-edge tables.
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
flight=(flight --camera "$OUT/data/camera_nominal.yaml" --data "$OUT/data" --base III,IV)
"$AEROCAL" --quiet "${flight[@]}" --out "$OUT/adjusted" --no-report >/dev/null
# The first patch of each CCD and axis (8 of the 33: each run reads the adjusted result). A patch's
# tile in the mosaics (112 px a side, 8 a row) is a window of its image: the file's origin in the
# sub-image (or virtual image) is the patch's origin less the tile's place in the mosaic.
adjusted="$OUT/adjusted/result.json"
while read -r target image ccd raw_file raw_origin virtual_origin; do
  "$AEROCAL" --quiet quality mtf --image "$OUT/data/edge_targets/$raw_file" --sub-image "$ccd" \
    --targets "$OUT/data/edge_targets/targets.csv" --target "$target" --image-id "$image" \
    --camera "$OUT/adjusted/camera_calibrated.yaml" --orientation "$adjusted" --mapping "$adjusted" \
    --image-origin "$raw_origin" --virtual-image "$OUT/data/edge_targets/virtual.tif" \
    --virtual-origin "$virtual_origin" --flight-axis x --pixel-size-mm 0.009 \
    --out "$OUT/quality/targets_${target}_$image.json" >/dev/null
  results+=(--quality "$OUT/quality/targets_${target}_$image.json")
done < <(awk -F, 'function origin(col, row, rc, rr) { return (col - int(rc / 112) * 112) "," (row - int(rr / 112) * 112) }
                  NR > 2 && !seen[$3 "/" $4]++ { print $1, $2, $3, $5, origin($15, $16, $6, $7), origin($17, $18, $11, $12) }' \
           "$patches")
"$AEROCAL" "${flight[@]}" --out "$OUT/flight" --certificate "${results[@]}"
python3 - "$OUT/quality" "$OUT/flight/result.json" <<'PY'
import json, pathlib, sys
for path in sorted(p for p in pathlib.Path(sys.argv[1]).glob("*.json") if not p.stem.startswith("targets_")):
    doc = json.loads(path.read_text())
    for axis, a in sorted(doc["axes"].items()):
        print(f"{path.stem:8s} {axis} ({a['direction']:12s}) {a['count']:2d} edges: MTF50 "
              f"{a['mtf50_cy_px']:.4f} +- {a['mtf50_expanded_cy_px']:.4f} cycles/px (k = 2)")
# The resampling loss as result.json (and report.html, the certificate) state it.
section = json.loads(pathlib.Path(sys.argv[2]).read_text())["dynamic_image_resolution"]
for r in section["resampling_loss"]:
    print(f"loss {r['axis']} ({r['direction']:12s}): raw mean {r['raw_mean_mtf50_cy_px']:.4f}, virtual "
          f"{r['virtual_mtf50_cy_px']:.4f}: {r['loss_cy_px']:.4f} +- {r['loss_expanded_cy_px']:.4f} cycles/px, "
          f"{r['loss_percent']:.2f} +- {r['loss_expanded_percent']:.2f} % (k = 2)")
# Per CCD and axis, the edges found from their targets (step 4): measured against predicted loss.
for r in section["resampling_per_sub_image"]:
    print(f"CCD {r['sub_image']:3s} {r['axis']} ({r['direction']:12s}) {r['edges']} edge(s): raw MTF50 "
          f"{r['raw_mean_mtf50_cy_px']:.4f}, virtual {r['virtual_mean_mtf50_cy_px']:.4f}: loss "
          f"{r['mean_loss_percent']:.2f} %, predicted {r['mean_predicted_loss_percent']:.2f} % at the mapping's shifts")
PY
