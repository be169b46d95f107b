#!/usr/bin/env bash
# How much the head changes the error against the path-traced ground truth and the frame time
# (issue 40): straight.hair under each shared map, single scattering, Chiang `brown`, 160×120,
# without a head and with the ellipsoid fitted to the roots; each frame measured by `compare`
# against a Mitsuba render of the same scene (the head in it too). Writes
# out/head-error/MAP-HEAD.json (compare's report) and prints one table row per map.
#
#   scripts/head-error.sh [MAP_FILE ...]     (default: the eight maps; ~6 min a map here)
#
# STRANDLIGHT: the binary (default target/release/strandlight); TRUTH_SPP: the truth's most
# samples per pixel (default 1024: its noise is reported and taken out of the error); HEADS:
# which heads (default "none ellipsoid").
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${STRANDLIGHT:-target/release/strandlight}
DATA=${STRANDLIGHT_SHARED_DATA:-../shared/data}
SPP=${TRUTH_SPP:-1024}
HEADS=${HEADS:-none ellipsoid}
OUT=out/head-error
mkdir -p "$OUT"
MAPS=("$@")
if [ ${#MAPS[@]} -eq 0 ]; then
  MAPS=(hdr_overcast_soil_puresky_1k.hdr quarry_01_1k.hdr photo_studio_01_1k.hdr moonless_golf_1k.hdr
        royal_esplanade_1k.hdr spruit_sunrise_1k.hdr venice_sunset_1k.hdr piz_compressed.exr)
fi
for map in "${MAPS[@]}"; do
  for head in $HEADS; do
    stem="$OUT/${map%.*}-$head"
    [ -s "$stem.json" ] && continue
    "$BIN" compare --hair "$DATA/hair/straight.hair" --env "$DATA/envmaps/$map" --shading chiang \
      --modes single --size 160x120 --reference-lights 96 --ground-truth render \
      --truth-max-spp "$SPP" --head "$head" --out "$stem" --json > "$stem.json.part" 2> "$stem.log"
    mv "$stem.json.part" "$stem.json"
  done
done
python3 - "$OUT" "${MAPS[@]}" <<'PY'
import json, sys
out, maps = sys.argv[1], sys.argv[2:]
print("| map | SRBF ms, no head → head | SRBF vs truth (n.c.), no head → head | HDR-FLIP | DOM ref. (96) vs truth, no head → head | Mitsuba s |")
print("|---|---|---|---|---|---|")
for m in maps:
    stem = m.rsplit(".", 1)[0]
    try:
        a = json.load(open(f"{out}/{stem}-none.json"))["single"]
        b = json.load(open(f"{out}/{stem}-ellipsoid.json"))["single"]
    except FileNotFoundError:
        continue
    ta, tb = a["ground_truth"], b["ground_truth"]
    print(f"| {stem} | {a['srbf']['ms']:.0f} → {b['srbf']['ms']:.0f} | "
          f"{ta['srbf']['relative_rmse_noise_corrected']:.4f} → {tb['srbf']['relative_rmse_noise_corrected']:.4f} | "
          f"{ta['srbf']['hdr_flip']:.4f} → {tb['srbf']['hdr_flip']:.4f} | "
          f"{ta['reference']['relative_rmse_noise_corrected']:.4f} → {tb['reference']['relative_rmse_noise_corrected']:.4f} | "
          f"{ta['seconds']:.0f} / {tb['seconds']:.0f} |")
PY
