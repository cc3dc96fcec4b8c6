#!/usr/bin/env bash
# Installs everything sfmeval's build and tests need on a fresh Debian 12 machine with Rust, Python
# 3.11 and Node 20: apt packages, the wasm32 target, and the Python venv (.venv) with the SfM tools,
# Blender-as-a-module and the reference implementations the tests compare with. Idempotent: tools
# already present are reused.
set -euo pipefail
cd "$(dirname "$0")/.."
t0=$SECONDS

# wasm-bindgen-cli compiles (about 3 minutes of both cores) while apt, pip and npm download;
# awaited before scripts/setup-extra.sh, which then finds it installed.
wb_log=$(mktemp)
scripts/install-wasm-bindgen.sh >"$wb_log" 2>&1 &
wb_pid=$!

# --- apt -------------------------------------------------------------------
apt_pkgs=(libusb-1.0-0 libgl1 libegl1 libxrender1 libxi6 libxkbcommon0 libsm6 libxxf86vm1 libxfixes3)
for f in requirements/apt-*.txt; do
  [ -f "$f" ] || continue
  while read -r p; do [[ -n "$p" && "$p" != \#* ]] && apt_pkgs+=("$p"); done < "$f"
done
missing=()
for p in "${apt_pkgs[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: apt-get install ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# ETH3D's evaluation tool, the reference of `sfmeval eth3d` (about 45 s on two cores, once).
scripts/build-eth3d-tool.sh

# --- Rust ------------------------------------------------------------------
rustup target list --installed | grep -q wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown
# the standard library's source: the page's threaded wasm rebuilds std with atomics (-Z build-std)
rustup component list --installed | grep -q '^rust-src' || rustup component add rust-src

# --- Python venv -----------------------------------------------------------
if [ ! -x .venv/bin/python ]; then
  python3.11 -m venv .venv 2>/dev/null || python3 -m venv .venv
fi
req_args=()
for f in requirements/*.txt; do
  case "$f" in requirements/apt-*) continue ;; esac
  req_args+=(-r "$f")
done
stamp=.venv/.requirements.sha
want=$(cat requirements/*.txt | sha256sum | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  .venv/bin/pip install -q --disable-pip-version-check "${req_args[@]}"
  echo "$want" > "$stamp"
fi

# --- Node tools (browser tests), when the page exists ------------------------
for d in www crates/sfmeval-wasm/js tests/browser; do
  if [ -f "$d/package-lock.json" ]; then (cd "$d" && npm ci --no-audit --no-fund --silent); fi
done
if ! wait "$wb_pid"; then
  cat "$wb_log"; echo "setup: installing wasm-bindgen-cli failed"; exit 1
fi
cat "$wb_log"
[ -x scripts/setup-extra.sh ] && scripts/setup-extra.sh
echo "setup: done in $((SECONDS - t0)) s"
