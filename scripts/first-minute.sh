#!/usr/bin/env bash
# A new user's first minute (issue 63), from a fresh clone with no out/: the release build, the
# demo's first PNG (the first look from coarse tables) and its full frame, the viewer's first lit
# frame and its convergence at 800x600 under Xvfb as the very first command (lavapipe's shader
# cache empty too), on an empty table cache after demo and again on a warm one, and
# the page's first preview in headless Chromium (WebGPU on SwiftShader). Prints a markdown
# table for the README.
#   git clone REPO fresh && cd fresh && scripts/first-minute.sh
#   (needs xvfb-run, chromium and node; the harness is installed when missing)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -e out ]; then
  echo "error: out/ exists; run this in a fresh clone, whose caches are empty" >&2
  exit 1
fi
work=$(mktemp -d /tmp/strandlight-first-minute.XXXXXX)
now() { date +%s.%N; }
since() { python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$1" "$(now)"; }
bin=target/release/strandlight
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
# lavapipe compiles each shader with LLVM the first time it draws with it and keeps the result in
# Mesa's shader cache (~/.cache/mesa_shader_cache): a fresh machine's is empty, so each run here
# starts from one of its own. demo, the README's first command, fills it for the rows after it.
export MESA_SHADER_CACHE_DIR="$work/driver-cache"

t=$(now)
cargo build --quiet --release -p strandlight
build=$(since "$t")
echo "release build $build s" >&2

t=$(now)
$bin demo >"$work/demo.txt"
demo_total=$(since "$t")
demo_first=$(grep -o 'coarse tables) [0-9.]* s after the start' "$work/demo.txt" | grep -o '[0-9.]* s' | cut -d' ' -f1)
echo "demo: first PNG $demo_first s, full frame $demo_total s" >&2

view() { # CACHE REPORT: the default view until converged (its screenshot closes the window)
  local t0
  t0=$(now)
  xvfb-run -a -s "-screen 0 1600x1000x24" $bin view --size 800x600 --cache "$1" \
    --report "$2" --screenshot "${2%.json}" >"$work/view.txt" 2>&1
  since "$t0"
}
# The viewer as a new user's very first command: the driver's shader cache is empty too.
first_total=$(MESA_SHADER_CACHE_DIR="$work/driver-cache-view" view "$work/view-first-cache" "$work/view-first.json")
cold_total=$(view "$work/view-cache" "$work/view-cold.json")
warm_total=$(view "$work/view-cache" "$work/view-warm.json")
cp "$work/view-warm.png" "$work/view.png"

scripts/web.sh --page-only >/dev/null
[ -d web/harness/node_modules ] || npm ci --prefix web/harness --no-audit --no-fund --silent
$bin web --out "$work/site" >/dev/null
$bin serve "$work/site" --port 0 >"$work/serve.txt" &
server=$!
trap 'kill $server 2>/dev/null || true' EXIT
sleep 1
url=$(grep -o 'http://[^ ]*' "$work/serve.txt")
mkdir -p "$work/page"
node web/harness/first_look.mjs "$url" "$work/page" 900 >/dev/null

python3 - "$work" "$build" "$demo_first" "$demo_total" "$first_total" "$cold_total" "$warm_total" <<'PY'
import json, sys
work, build, demo_first, demo_total, first_total, cold_total, warm_total = sys.argv[1:]
first = json.load(open(f"{work}/view-first.json"))
cold = json.load(open(f"{work}/view-cold.json"))
warm = json.load(open(f"{work}/view-warm.json"))
page = json.load(open(f"{work}/page/report.json"))["timing"]
def lit(r):
    tables = "coarse" if r["first_lit_coarse_tables"] else "full"
    return f"{r['first_lit_seconds']:.1f} s ({tables} tables)"
print(f"adapter: {warm['adapter']}")
print()
print("| step | first picture | complete |")
print("|---|---|---|")
print(f"| release build (fresh clone) | — | {build} s |")
print(f"| `demo`, empty cache | {demo_first} s (`out/demo-preview.png`) | {demo_total} s (`out/demo.png`) |")
print(f"| `view` as the first command, 800×600: every cache empty, lavapipe's shader cache too | {lit(first)} | {first_total} s (converged, window closed) |")
print(f"| `view`, 800×600, empty cache (after `demo`) | {lit(cold)} | {cold_total} s |")
print(f"| `view`, 800×600, tables cached | {lit(warm)} | {warm_total} s |")
print(f"| the page, headless Chromium, bundle served | {page['firstPreviewMs'] / 1e3:.1f} s | {page['convergedMs'] / 1e3:.1f} s |")
PY
echo "the viewer's converged frame: $work/view.png; the page: $work/page/whole-page.png" >&2
