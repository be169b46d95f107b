#!/usr/bin/env bash
# Builds the web page and its site:
#   scripts/web.sh [ARGS…]      the page, then `strandlight web ARGS…` (default: --out site)
#   scripts/web.sh --page-only  the page only (target/web/pkg), as CI does before the tests
# The page is the strandlight-web crate for wasm32, wrapped by wasm-bindgen's CLI at the
# version Cargo.lock pins (installed here when missing: about three minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."

version=$(grep -A1 '^name = "wasm-bindgen"$' Cargo.lock | sed -n 's/^version = "\(.*\)"/\1/p')
if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  rustup target add wasm32-unknown-unknown
fi
if [ "$(wasm-bindgen --version 2>/dev/null | cut -d' ' -f2)" != "$version" ]; then
  # Only the binary the build needs, unoptimized: it builds in 80 s instead of 3 min, and
  # wraps the module in seconds all the same.
  cargo install --quiet --debug wasm-bindgen-cli --version "$version" --no-default-features --bin wasm-bindgen
fi
cargo build --quiet -p strandlight-web --target wasm32-unknown-unknown --profile web
# The page goes where `strandlight web --page` looks by default, wherever cargo builds.
wasm-bindgen --target web --no-typescript --out-dir target/web/pkg \
  "${CARGO_TARGET_DIR:-target}/wasm32-unknown-unknown/web/strandlight_web.wasm"
echo "page: target/web/pkg ($(du -h target/web/pkg/strandlight_web_bg.wasm | cut -f1) of wasm)"

if [ "${1:-}" = "--page-only" ]; then
  exit 0
fi
if [ $# -eq 0 ]; then
  set -- --out site
fi
cargo run --quiet --release -p strandlight -- web "$@"
