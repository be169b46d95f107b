#!/usr/bin/env bash
# The env-lit view against the path-traced truth on every shared map: the opaque, layered and
# occupancy views with each lobe visibility, single and full scattering, 160×120, Chiang
# `brown` (eval/examples/view_study.rs; docs/BENCHMARKS.md, "The view: layers"). Needs the
# truths cached (`strandlight truth --size 160x120 ...` or an earlier `compare`/`bench --truth`,
# about 5 minutes a map). Prints one JSON line per frame to OUT (default out/view-error.jsonl).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/view-error.jsonl}
DATA=${STRANDLIGHT_SHARED_DATA:-../shared/data}
MAPS=${MAPS:-"hdr_overcast_soil_puresky_1k.hdr quarry_01_1k.hdr photo_studio_01_1k.hdr moonless_golf_1k.hdr royal_esplanade_1k.hdr spruit_sunrise_1k.hdr venice_sunset_1k.hdr piz_compressed.exr"}
cargo build --release -p strandlight-eval --example view_study
STUDY=${CARGO_TARGET_DIR:-target}/release/examples/view_study
: > "$OUT"
for map in $MAPS; do
  for mode in single full; do
    "$STUDY" "$DATA/envmaps/$map" "$mode" opaque/volume opaque/light-maps layered/volume \
      layered/light-maps | grep '^{' >> "$OUT"
    RUNS=1 "$STUDY" "$DATA/envmaps/$map" "$mode" occupancy/light-maps | grep '^{' >> "$OUT"
  done
done
echo "wrote $OUT"
