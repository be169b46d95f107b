#!/usr/bin/env bash
# Where the error against the path-traced truth lives (docs/BENCHMARKS.md, "Fiber scale"): piz,
# single scattering, Chiang `brown`, the defaults.
#  1. A sparse groom (every 20th strand of straight.hair): `compare` against its truth, so the
#     view's coverage and the shading are measured with little self-shadowing or overlap.
#  2. straight.hair rendered at 160x120, 320x240 and 640x480, each box-filtered to 160x120
#     (supersampled), against the 640x480 truth box-filtered to 160x120 (5120 spp a pixel).
# Then each frame's error per pixel and over blocks (scripts/fiber_scale_error.py). About 4 min
# on 2 cores with the truths cached (first run: + ~3 min for Mitsuba).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${STRANDLIGHT_SHARED_DATA:-../shared/data}
OUT=${1:-out/fiber-scale}
ENV=$DATA/envmaps/piz_compressed.exr
PY=${STRANDLIGHT_PYTHON:-python3}
mkdir -p "$OUT"
cargo build --release -p strandlight
cargo build --release -p strandlight-eval --example thin_groom
BIN=${CARGO_TARGET_DIR:-target}/release/strandlight
SCENE=(--shading chiang --env "$ENV")

"${CARGO_TARGET_DIR:-target}/release/examples/thin_groom" "$DATA/hair/straight.hair" "$OUT/thin20.hair" 20
"$BIN" compare "${SCENE[@]}" --hair "$OUT/thin20.hair" --size 160x120 --modes single \
  --reference-lights 1536 --ground-truth render --truth-max-spp 4096 --out "$OUT/thin" >/dev/null
"$BIN" render env "${SCENE[@]}" --hair "$OUT/thin20.hair" --size 160x120 --scattering single \
  --lobe-visibility light-maps --kappa 1 --out "$OUT/thin/light-maps-kappa-1" >/dev/null 2>&1

"$BIN" truth --env "$ENV" --hair "$DATA/hair/straight.hair" --size 640x480 --modes single \
  --truth-max-spp 256 --out "$OUT/dense" >/dev/null
frames=()
for visibility in volume light-maps; do
  for size in 160x120 320x240 640x480; do
    stem=$OUT/dense/$visibility-$size
    "$BIN" render env "${SCENE[@]}" --hair "$DATA/hair/straight.hair" --size "$size" \
      --scattering single --lobe-visibility "$visibility" --out "$stem" --json >"$stem.log" 2>"$stem.err"
    echo "$visibility $size: $(grep -o '"frame_ms": [0-9.]*' "$stem.log")"
    frames+=("$stem.exr")
  done
done

echo "sparse groom, 160x120:"
"$PY" scripts/fiber_scale_error.py blocks "$OUT/thin/single-truth.exr" 160 \
  "$OUT/thin/single-srbf.exr" "$OUT/thin/light-maps-kappa-1.exr" "$OUT/thin/single-reference.exr"
echo "straight.hair, box-filtered to 160x120:"
"$PY" scripts/fiber_scale_error.py blocks "$OUT/dense/single-truth.exr" 160 "${frames[@]}"
