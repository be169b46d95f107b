#!/bin/bash
# BENCHMARKS history ("Compact source's shadow: the map size", docs/history/benchmarks-to-2026-11-28.md): the SRBF default (the volume) and the
# 96-light DOM reference against the path-traced truth, single scattering, 160x120, by the size
# of the light maps (with the volume, only the compact sources draw any). Renders each map's
# truth once (cached). Usage: scripts/compact-source-map-size.sh [OUT_DIR]
set -euo pipefail
out=${1:-out/compact-source-map-size}
mkdir -p "$out"
run() {
  echo "$(date +%T) $1 $2" >&2
  ./target/release/strandlight compare --hair ../shared/data/hair/straight.hair \
    --env "../shared/data/envmaps/$1" --shading chiang --ground-truth render \
    --reference-lights 96 --modes single --size 160x120 --light-map-size "$2" --json \
    --out "$out/out-$1-$2" > "$out/$1-$2.json"
}
for s in 256 512 1024 2048; do run quarry_01_1k.hdr $s; done
for m in photo_studio_01_1k.hdr royal_esplanade_1k.hdr moonless_golf_1k.hdr spruit_sunrise_1k.hdr piz_compressed.exr; do
  for s in 256 512; do run "$m" $s; done
done
python3 - "$out" <<'PY'
import glob, json, os, sys
for f in sorted(glob.glob(os.path.join(sys.argv[1], '*.json'))):
    s = json.load(open(f))['single']
    t, r = s['ground_truth']['srbf'], s['ground_truth']['reference']
    print(f"{os.path.basename(f)[:-5]:40s} {s['srbf']['ms']:6.0f} ms  SRBF {t['relative_rmse_noise_corrected']:.4f} / {t['hdr_flip']:.4f}"
          f"  DOM {r['relative_rmse_noise_corrected']:.4f} / {r['hdr_flip']:.4f}")
PY
