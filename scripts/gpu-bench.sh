#!/usr/bin/env bash
# The figures a real GPU is lent for, in one call (issue 40 §6), under 8 minutes on a GPU machine:
#   1. the env-lit frame on straight.hair at 1920×1080, single and single + multiple scattering,
#      in frames per second (median of GPU_BENCH_RUNS `render env` frames; setup excluded);
#   2. the viewer's time to its first preview and to converged (under Xvfb when there is no
#      display; skipped with a line when neither exists);
#   3. the Hunz table's point-light rows (runtime/examples/render_bench.rs);
#   4. the host example's frame (runtime/examples/host.rs: the hair drawn into another
#      application's render pass), on the GPU alone and with the frame read back.
# Writes OUT/summary.md (the rows BENCHMARKS takes) beside every raw JSON, and prints it.
#
#   scripts/gpu-bench.sh [OUT]            # default out/gpu-bench
#   GPU_BENCH_SIZE=320x180 scripts/gpu-bench.sh   # a quick end-to-end check on lavapipe
#
# wgpu picks the adapter (WGPU_ADAPTER_NAME / WGPU_BACKEND choose another); every JSON names it.
set -euo pipefail
cd "$(dirname "$0")/.."

OUT=${1:-out/gpu-bench}
SIZE=${GPU_BENCH_SIZE:-1920x1080}
RUNS=${GPU_BENCH_RUNS:-3}
MAP=${GPU_BENCH_MAP:-procedural:sun_and_sky}
DATA=${STRANDLIGHT_SHARED_DATA:-../shared/data}
HAIR="$DATA/hair/straight.hair"
mkdir -p "$OUT"
started=$(date +%s)

if [[ ! -f "$HAIR" ]]; then
  echo "gpu-bench: $HAIR not found (set STRANDLIGHT_SHARED_DATA); using the procedural groom" >&2
  HAIR_ARGS=()
else
  HAIR_ARGS=(--hair "$HAIR")
fi

echo "== build (release)" >&2
cargo build --release --quiet -p strandlight --bin strandlight
cargo build --release --quiet -p strandlight-runtime --example render_bench
cargo build --release --quiet -p strandlight-runtime --example host
BIN=target/release/strandlight

echo "== 1. env-lit frame at $SIZE, $RUNS runs per mode" >&2
# The first call fits and bakes into out/cache; the timed frames only render.
"$BIN" render env --env "$MAP" "${HAIR_ARGS[@]}" --size 160x120 --out "$OUT/warm" >/dev/null
for mode in single full; do
  for i in $(seq 1 "$RUNS"); do
    "$BIN" render env --env "$MAP" "${HAIR_ARGS[@]}" --size "$SIZE" --scattering "$mode" \
      --out "$OUT/env-$mode" --json >"$OUT/env-$mode-$i.json"
  done
done

echo "== 2. viewer: first preview and converged at $SIZE" >&2
echo '[{"wait": "converged"}]' >"$OUT/view-script.json"
VIEW=("$BIN" view --env "$MAP" "${HAIR_ARGS[@]}" --size "$SIZE" --script "$OUT/view-script.json"
  --report "$OUT/view-report.json" --timeout-s 400)
if [[ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]]; then
  "${VIEW[@]}" >"$OUT/view.log" 2>&1 || echo "gpu-bench: the viewer failed (see $OUT/view.log)" >&2
elif command -v xvfb-run >/dev/null; then
  xvfb-run -a -s "-screen 0 2800x1400x24" "${VIEW[@]}" >"$OUT/view.log" 2>&1 ||
    echo "gpu-bench: the viewer failed (see $OUT/view.log)" >&2
else
  echo "gpu-bench: no display and no xvfb-run: the viewer's row is skipped" >&2
fi

echo "== 3. the Hunz table's point-light rows" >&2
target/release/examples/render_bench "$RUNS" >"$OUT/render_bench.txt"

echo "== 4. the host example's frame at $SIZE" >&2
"$BIN" render env --env "$MAP" "${HAIR_ARGS[@]}" --size "$SIZE" --out "$OUT/host-settings" >/dev/null
target/release/examples/host --settings "$OUT/host-settings.json" --out "$OUT/host" \
  --time "$RUNS" | grep "^host frame" >"$OUT/host.txt"

python3 - "$OUT" "$SIZE" "$RUNS" "$MAP" "$(($(date +%s) - started))" <<'EOF' | tee "$OUT/summary.md"
import json, pathlib, statistics, sys
out, size, runs, env_map, seconds = pathlib.Path(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
reports = {m: [json.loads((out / f"env-{m}-{i}.json").read_text()) for i in range(1, runs + 1)] for m in ("single", "full")}
adapter = reports["full"][0]["adapter"]
print(f"### GPU bench on {adapter}\n")
print(f"`scripts/gpu-bench.sh`, {size}, {runs} runs per row (medians), map {env_map}, hair {reports['full'][0]['hair']}; {seconds} s in all.\n")
print("| what | median ms | frames per second |")
print("|---|---:|---:|")
for mode, label in (("single", "env-lit frame, single scattering"), ("full", "env-lit frame, single + multiple scattering")):
    ms = statistics.median(r["frame_ms"] for r in reports[mode])
    print(f"| {label} | {ms:.1f} | {1000.0 / ms:.2f} |")
view = out / "view-report.json"
if view.exists():
    v = json.loads(view.read_text())
    if v.get("requests"):
        r = v["requests"][0]
        preview = r.get("preview_seconds")
        print(f"| viewer: first preview | {1000 * preview:.0f} | |" if preview else "| viewer: first preview | (none) | |")
        print(f"| viewer: converged | {1000 * r['converged_seconds']:.0f} | |")
    print(f"\nViewer adapter: {v.get('adapter')}; window: {v.get('window_adapter')}.")
else:
    print("\nViewer: not measured (no display).")
print(f"\nHost example (`runtime/examples/host.rs --time {runs}`): " + (out / "host.txt").read_text().strip())
print("\nPoint-light rows (`cargo run --release -p strandlight-runtime --example render_bench`):\n")
print("```")
print((out / "render_bench.txt").read_text().rstrip())
print("```")
EOF
