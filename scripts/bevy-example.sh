#!/usr/bin/env bash
# strandlight's exported LUTs in Bevy (engines/bevy/README.md): builds the CLI and the Bevy
# example (its own workspace, outside CI), renders strandlight's unshadowed frame of a groom
# under an environment's SRBF fit, exports the convolution table as KTX2, renders the same scene
# in Bevy with a material that samples it through strandlight_lut.wgsl, and compares the two.
# Prints the figures; writes out/bevy/side_by_side.png (strandlight | Bevy | |difference| × 10
# on the compared pixels; side_by_side-KIND.png with a deliberate error); exits nonzero when the
# frames do not match.
#
#   scripts/bevy-example.sh                              # the comparison (passes)
#   scripts/bevy-example.sh --deliberate-error mirror    # lights mirrored left–right (fails)
#   scripts/bevy-example.sh --deliberate-error swap-axes # the LUT's u·ξ and u·ω_o swapped (fails)
#
# Environment: STRANDLIGHT_SHARED_DATA (default ../shared/data), HAIR (a Yuksel .hair; default
# Bangs_100.hair), MAP (default venice_sunset_1k.hdr: its fit has no compact sources), SIZE
# (default 320x240), STRANDLIGHT (a built CLI: skips its build). Needs a Vulkan device (lavapipe
# on a machine without a GPU); no window.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
ERROR=none
while [ $# -gt 0 ]; do
  case "$1" in
    --deliberate-error) ERROR=${2:-mirror}; shift 2 || shift ;;
    *) echo "usage: $0 [--deliberate-error mirror|swap-axes]" >&2; exit 2 ;;
  esac
done
DATA=$(cd "${STRANDLIGHT_SHARED_DATA:-../shared/data}" && pwd)
HAIR=${HAIR:-$DATA/hair/Bangs_100.hair}
MAP=${MAP:-$DATA/envmaps/venice_sunset_1k.hdr}
SIZE=${SIZE:-320x240}
OUT=$ROOT/out/bevy
mkdir -p "$OUT"
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}

if [ -z "${STRANDLIGHT:-}" ]; then
  cargo build --release -p strandlight
  STRANDLIGHT=${CARGO_TARGET_DIR:-target}/release/strandlight
fi
STRANDLIGHT=$(cd "$(dirname "$STRANDLIGHT")" && pwd)/$(basename "$STRANDLIGHT")
start=$(date +%s)
cargo build --manifest-path engines/bevy/Cargo.toml
echo "bevy example build: $(( $(date +%s) - start )) s"
BEVY=$(cd "${CARGO_TARGET_DIR:-engines/bevy/target}" && pwd)/debug/strandlight-bevy

# The scene, written as strandlight's own settings: exact camera, single scattering,
# `shadowed: false`, the nearest fiber per pixel, fibers 1 px wide.
"$BEVY" scene --hair "$HAIR" --env "$MAP" --size "$SIZE" --fiber-width-px 1 --out "$OUT/settings.json"

# strandlight's unshadowed frame. Run inside out/bevy, so that its fit and table caches
# (out/cache, relative to the working directory) are this script's own: the fit Bevy reads is
# the one this frame was lit with.
(cd "$OUT" && "$STRANDLIGHT" render replay settings.json --out strandlight) 2>&1 | grep -v XDG_RUNTIME_DIR
map_name=$(basename "$MAP")
mapfile -t fits < <(grep -l "\"source\": *\"$map_name\"" "$OUT"/out/cache/fits/*.srbf.json)
if [ "${#fits[@]}" -ne 1 ]; then
  echo "expected one cached fit of $map_name in $OUT/out/cache/fits, found ${#fits[@]}" >&2
  exit 1
fi
FIT=${fits[0]}

# The env frame's table as another engine gets it: KTX2 + sidecar + strandlight_lut.wgsl (the
# fiber the frame used: Chiang, `brown`; the λ axis spans the fit's range, as the render's).
if [ ! -f "$OUT/tables/ktx2/chiang.json" ] || [ "$FIT" -nt "$OUT/tables/ktx2/chiang.json" ]; then
  "$STRANDLIGHT" bake --model chiang --preset brown --srbf "$FIT" --export ktx2 --out "$OUT/tables" \
    | tail -n 2
fi

# The exported table must be the one the frame was shaded with (same axes, same values).
rendered_table=$(ls "$OUT"/out/cache/tables/*/chiang.sltab | head -n 1)
if ! diff <("$STRANDLIGHT" inspect "$rendered_table") <("$STRANDLIGHT" inspect "$OUT/tables/chiang.sltab") >/dev/null; then
  echo "the exported table differs from the one strandlight's frame used ($rendered_table)" >&2
  exit 1
fi

suffix=$([ "$ERROR" = none ] || echo "-$ERROR")
"$BEVY" render --settings "$OUT/settings.json" --fit "$FIT" --lut "$OUT/tables/ktx2" \
  --table chiang --deliberate-error "$ERROR" --out "$OUT/bevy$suffix.exr" \
  2> >(grep -v XDG_RUNTIME_DIR >&2)
"$BEVY" compare --settings "$OUT/settings.json" --strandlight "$OUT/strandlight.exr" \
  --bevy "$OUT/bevy$suffix.exr" --png "$OUT/side_by_side$suffix.png"
