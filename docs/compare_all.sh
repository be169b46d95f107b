#!/usr/bin/env bash
# Regenerates the env-lit comparison table of docs/BENCHMARKS.md: `strandlight compare` on
# straight.hair under every shared map (../shared/data), single and full scattering, then the
# markdown table (`strandlight compare-table`).
# Usage: docs/compare_all.sh [REFERENCE_LIGHTS (default 384)] [MAP_FILE ...(default: every map)]
#   COMPARE_ARGS="--equal-error" docs/compare_all.sh 384 quarry_01_1k.hdr   adds flags to compare;
#   BENCH_DIR=out/bench-paper COMPARE_ARGS="--sources 0" docs/compare_all.sh   the paper's pure SRBF fit.
# Results: $BENCH_DIR/<map>.json (one compare --json each; BENCH_DIR defaults to out/bench), the
# images in $BENCH_DIR/<map>/, and $BENCH_DIR/table.md over every $BENCH_DIR/*.json present.
set -euo pipefail
cd "$(dirname "$0")/.."
data=../shared/data
if [ ! -d "$data" ]; then echo "skipped: $data is absent (see README: Test data)"; exit 0; fi
lights=${1:-384}
shift || true
maps=("$@")
if [ ${#maps[@]} -eq 0 ]; then
  maps=(quarry_01_1k.hdr photo_studio_01_1k.hdr hdr_overcast_soil_puresky_1k.hdr moonless_golf_1k.hdr
        royal_esplanade_1k.hdr spruit_sunrise_1k.hdr venice_sunset_1k.hdr piz_compressed.exr)
fi
cargo build --release --quiet
bin=${CARGO_TARGET_DIR:-target}/release/strandlight
bench=${BENCH_DIR:-out/bench}
mkdir -p "$bench"
for m in "${maps[@]}"; do
  name=${m%.*}
  echo "== $name ($lights reference lights) $(date -u +%H:%M:%S)" >&2
  # shellcheck disable=SC2086 # COMPARE_ARGS is a list of flags
  "$bin" compare --hair "$data/hair/straight.hair" --env "$data/envmaps/$m" --reference-lights "$lights" \
    --timing-runs 1 --json --out "$bench/$name" ${COMPARE_ARGS:-} > "$bench/$name.json.part"
  mv "$bench/$name.json.part" "$bench/$name.json"
done
"$bin" compare-table "$bench"/*.json | tee "$bench/table.md"
