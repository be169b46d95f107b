#!/usr/bin/env bash
# Regenerates the env-lit comparison table of docs/BENCHMARKS.md: `strandlight compare` on
# straight.hair under every shared map (../shared/data), single and full scattering.
# Usage: docs/compare_all.sh [REFERENCE_LIGHTS_FOR_THE_THREE_TARGET_MAPS] [REFERENCE_LIGHTS_FOR_THE_OTHERS]
# Results: out/bench/<map>.json (one compare --json each) and the images in out/bench/<map>/.
set -euo pipefail
cd "$(dirname "$0")/.."
data=../shared/data
if [ ! -d "$data" ]; then echo "skipped: $data is absent (see README: Test data)"; exit 0; fi
target_lights=${1:-384}
other_lights=${2:-96}
cargo build --release --quiet
bin=${CARGO_TARGET_DIR:-target}/release/strandlight
mkdir -p out/bench
run() {
  local map=$1 lights=$2 name
  name=$(basename "$map" | sed 's/\.[a-z]*$//')
  echo "== $name ($lights reference lights) $(date -u +%H:%M:%S)" >&2
  "$bin" compare --hair "$data/hair/straight.hair" --env "$map" --reference-lights "$lights" \
    --timing-runs 1 --json --out "out/bench/$name" > "out/bench/$name.json"
}
for m in quarry_01_1k.hdr photo_studio_01_1k.hdr hdr_overcast_soil_puresky_1k.hdr; do run "$data/envmaps/$m" "$target_lights"; done
for m in moonless_golf_1k.hdr royal_esplanade_1k.hdr spruit_sunrise_1k.hdr venice_sunset_1k.hdr piz_compressed.exr; do run "$data/envmaps/$m" "$other_lights"; done
