#!/bin/bash
# Both lobe-visibility estimators on every shared map, single and full scattering, against the
# cached ground truth and DOM references (run `bench --truth` first to cache them), then the
# table of docs/BENCHMARKS.md, "Lobe visibility". Usage: scripts/lobe-visibility.sh [OUT_DIR]
set -euo pipefail
out=${1:-out/lobe-visibility}
mkdir -p "$out"
# The reference's light budget is a settings-file field (compare --help, --settings).
echo '{"reference_max_lights": 1536}' > "$out/settings.json"
for m in hdr_overcast_soil_puresky_1k.hdr quarry_01_1k.hdr photo_studio_01_1k.hdr moonless_golf_1k.hdr \
         royal_esplanade_1k.hdr spruit_sunrise_1k.hdr venice_sunset_1k.hdr piz_compressed.exr; do
  for v in light-maps volume; do
    echo "$m, $v" >&2
    ./target/release/strandlight compare --hair ../shared/data/hair/straight.hair \
      --env "../shared/data/envmaps/$m" --shading chiang --ground-truth cached --truth-max-spp 4096 \
      --settings "$out/settings.json" --modes single,full --size 160x120 \
      --lobe-visibility "$v" --json --out "$out/out-$m-$v" > "$out/$m-$v.json"
  done
done
python3 scripts/lobe_visibility_table.py "$out"
