#!/usr/bin/env bash
# Multiple scattering by melanin (docs/BENCHMARKS.md): today's default frame of straight.hair at
# 160x120 against Mitsuba's truth, per map and Chiang preset, split into its single- and
# multiple-scattering parts by `image-error --single`. Prints one markdown row per map and
# preset: each part's light against the truth's part and its error over 16x16 blocks (over the
# full truth's norm), and the full frame's mean ratio and 16x16 error.
#
#   scripts/melanin-table.sh [OUT] [PRESETS] [MAPS]      PRESETS, MAPS: space-separated
#
# Truths at STRANDLIGHT_TRUTH_SPP (default 256) samples a pixel are cached in OUT/cache: over
# 16x16 blocks they differ from 1,280-spp truths by 0.005 (full) and 0.012 (single) of the
# truth's norm (white hair under venice). A map and preset whose row file
# exists is skipped, so a cut-off run goes on where it stopped. About 1-3 min a map and preset
# on 2 cores with nothing cached (white's full scattering, 64 bounces deep, is most).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${STRANDLIGHT_SHARED_DATA:-../shared/data}
OUT=${1:-out/melanin}
PRESETS=${2:-white blonde brown dark}
MAPS=${3:-venice_sunset_1k.hdr hdr_overcast_soil_puresky_1k.hdr quarry_01_1k.hdr spruit_sunrise_1k.hdr piz_compressed.exr photo_studio_01_1k.hdr moonless_golf_1k.hdr royal_esplanade_1k.hdr}
SPP=${STRANDLIGHT_TRUTH_SPP:-256}
HAIR=$DATA/hair/straight.hair
# STRANDLIGHT_BIN: a copy of the binary to measure (so that a build during the run cannot change it).
BIN=${STRANDLIGHT_BIN:-}
if [ -z "$BIN" ]; then
  cargo build --release -p strandlight
  BIN=${CARGO_TARGET_DIR:-target}/release/strandlight
fi
mkdir -p "$OUT/cache"

# The number after `word` in image-error's output, or "–" when the line is missing.
field() { grep -o "$2 [0-9.]*" <<<"$1" | head -n1 | awk '{print $NF}'; }

row() {
  local map=$1 preset=$2 name=${1%.*} dir=$OUT/${1%.*}-$2
  local row_file=$dir/row.md
  [ -s "$row_file" ] && { cat "$row_file"; return; }
  mkdir -p "$dir"
  "$BIN" truth --hair "$HAIR" --env "$DATA/envmaps/$map" --size 160x120 --preset "$preset" \
    --modes single,full --truth-max-spp "$SPP" --cache "$OUT/cache" --out "$dir/truth" \
    >"$dir/truth.log" 2>&1
  for mode in single full; do
    "$BIN" render env --hair "$HAIR" --env "$DATA/envmaps/$map" --camera perspective \
      --size 160x120 --shading chiang --preset "$preset" --scattering "$mode" \
      --out "$dir/$mode" >"$dir/$mode.out" 2>"$dir/$mode.err"
  done
  local report
  report=$("$BIN" image-error "$dir/full.exr" "$dir/truth/full-truth.exr" \
    --single "$dir/single.exr" "$dir/truth/single-truth.exr")
  echo "$report" >"$dir/image-error.txt"
  local single_line multiple_line
  single_line=$(grep '^single-scattering part' <<<"$report")
  multiple_line=$(grep '^multiple-scattering part' <<<"$report")
  local multiple_light
  multiple_light=$(grep -o '^[^:]*: [0-9.]*×' <<<"$multiple_line" | grep -o '[0-9.]*×' | tr -d '×')
  # Dark hair skips multiple scattering by the plan's decision: its frame's part is black.
  grep -q '^skipped multiple' "$dir/full.err" && multiple_light="0 (skipped)"
  printf '| %s | %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$preset" \
    "$(grep -o '[0-9.]*×' <<<"$single_line" | head -n1 | tr -d '×')" \
    "$(field "$single_line" '16×16')" "$multiple_light" "$(field "$multiple_line" '16×16')" \
    "$(field "$report" 'mean')" "$(field "$report" '16×16')" \
    | tee "$row_file"
}

echo "| map | preset | single: light | single: 16×16 | multiple: light | multiple: 16×16 | full: mean | full: 16×16 |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
for preset in $PRESETS; do
  for map in $MAPS; do
    row "$map" "$preset"
  done
done
