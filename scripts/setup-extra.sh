#!/usr/bin/env bash
# Extra setup for the browser page and the npm package (called by scripts/setup.sh):
# Debian's chromium + chromedriver (headless tests), and wasm-bindgen-cli pinned to the
# wasm-bindgen version in Cargo.lock, cargo-installed into .tools/. Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
missing=()
for p in chromium chromium-driver; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup-extra: apt-get install ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
rustup target list --installed | grep -q wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown
# the standard library's source: the page's threaded wasm rebuilds std with atomics (-Z build-std)
rustup component list --installed | grep -q '^rust-src' || rustup component add rust-src
scripts/install-wasm-bindgen.sh
for d in www crates/sfmeval-wasm/js tests/browser; do
  [ -f "$d/package-lock.json" ] && [ ! -d "$d/node_modules" ] && (cd "$d" && npm ci --no-audit --no-fund --silent)
done
echo "setup-extra: chromium $(chromium --version 2>/dev/null | awk '{print $2}'), wasm-bindgen $(.tools/bin/wasm-bindgen --version | awk '{print $2}')"
