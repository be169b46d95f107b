#!/usr/bin/env bash
# The web page's figures for docs/BENCHMARKS.md ("The page in a browser"): the site's size, and
# the time to the first preview and to converged in headless Chromium (WebGPU on SwiftShader)
# beside the desktop viewer on the same settings (Vulkan; lavapipe without a GPU), RUNS runs
# each, interleaved so that both see the same load. Prints a markdown table.
#   scripts/web-bench.sh [RUNS]   (default 3; needs xvfb-run, chromium, node and the harness:
#                                  npm ci --prefix web/harness; BIN=path/to/strandlight uses
#                                  that binary instead of building the release one)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
work=$(mktemp -d /tmp/strandlight-web-bench.XXXXXX)
scripts/web.sh --page-only >/dev/null
bin=${BIN:-target/release/strandlight}
if [ -z "${BIN:-}" ]; then
  cargo build --quiet --release -p strandlight
fi
$bin web --out "$work/site" >/dev/null
$bin serve "$work/site" --port 0 >"$work/serve.txt" &
server=$!
trap 'kill $server 2>/dev/null || true' EXIT
sleep 1
url=$(grep -o 'http://[^ ]*' "$work/serve.txt")
echo '[{"wait": "converged"}]' >"$work/script.json"
for i in $(seq "$runs"); do
  mkdir -p "$work/page$i"
  node web/harness/page_check.mjs "$url" "$work/page$i" 600 >/dev/null
  xvfb-run -a -s "-screen 0 1400x900x24" $bin view --replay "$work/site/bundle/settings.json" \
    --script "$work/script.json" --report "$work/view$i.json" >/dev/null 2>&1
done
cp "$work/page1/whole-page.png" "$work/page.png"
echo "the first run's page: $work/page.png" >&2
python3 - "$work" "$runs" <<'PY'
import json, os, statistics, sys
work, runs = sys.argv[1], int(sys.argv[2])
pages = [json.load(open(f"{work}/page{i}/report.json")) for i in range(1, runs + 1)]
views = [json.load(open(f"{work}/view{i}.json"))["requests"][0] for i in range(1, runs + 1)]
med = lambda xs: statistics.median(xs)
site = f"{work}/site"
size = lambda *names: sum(os.path.getsize(os.path.join(site, n)) for n in names)
tables = sum(os.path.getsize(os.path.join(site, "bundle/tables", f)) for f in os.listdir(f"{site}/bundle/tables"))
print(f"site: wasm {size('strandlight_web_bg.wasm') / 1e6:.2f} MB, glue {size('strandlight_web.js') / 1e3:.0f} kB, "
      f"page {size('index.html') / 1e3:.0f} kB, tables {tables / 1e6:.1f} MB, groom {size('bundle/hair.hair') / 1e6:.2f} MB, "
      f"settings + fit {size('bundle/settings.json', 'bundle/scene.json') / 1e3:.0f} kB; "
      f"adapter {pages[0]['describe']['adapter']}")
print()
print("| medians of %d | first preview (s) | converged (s) | longest main-thread tick (ms) | opening the bundle (ms) |" % runs)
print("|---|---|---|---|---|")
print("| page, headless Chromium, WebGPU on SwiftShader | %.1f | %.1f | %.0f (median %.0f) | %.0f |" % (
    med([p["timing"]["firstPreviewMs"] for p in pages]) / 1e3,
    med([p["timing"]["convergedMs"] for p in pages]) / 1e3,
    med([p["timing"]["longestTickMs"] for p in pages]),
    med([p["timing"]["medianTickMs"] for p in pages]),
    med([p["timing"]["loadMs"] for p in pages])))
print("| desktop viewer, Vulkan (lavapipe) | %.1f | %.1f | — (render thread) | — |" % (
    med([v["preview_seconds"] for v in views]), med([v["converged_seconds"] for v in views])))
PY
