#!/bin/bash
# BENCHMARKS "Options judged against the truth": each light-map option against the path-traced
# truth on venice, golf and spruit, single scattering, 160x120 (the truth is rendered once per
# map and cached). The options since removed need the revision before their removal (git log
# -S light_chord_tolerance). Usage: scripts/light-map-options.sh [OUT_DIR]
set -euo pipefail
out=${1:-out/light-map-options}
mkdir -p "$out"
for m in venice_sunset_1k.hdr moonless_golf_1k.hdr spruit_sunrise_1k.hdr; do
  while read -r name flags; do
    echo "$(date +%T) $m $name" >&2
    # shellcheck disable=SC2086 # the flags are words
    ./target/release/strandlight compare --hair ../shared/data/hair/straight.hair \
      --env "../shared/data/envmaps/$m" --shading chiang --ground-truth render --truth-max-spp 4096 \
      --reference-lights 96 --modes single --size 160x120 \
      $flags --json --out "$out/out-$m-$name" > "$out/$m-$name.json"
  done <<'V'
volume --lobe-visibility volume
light-maps --lobe-visibility light-maps
every-strand-0.5 --lobe-visibility light-maps --every-strand-share 0.5
V
done
python3 - "$out" <<'PY'
import glob, json, os, sys
for f in sorted(glob.glob(os.path.join(sys.argv[1], '*.json'))):
    s = json.load(open(f))['single']
    t = s['ground_truth']['srbf']
    print(f"{os.path.basename(f)[:-5]:45s} {s['srbf']['ms']:7.0f} ms  truth {t['relative_rmse_noise_corrected']:.4f}")
PY
