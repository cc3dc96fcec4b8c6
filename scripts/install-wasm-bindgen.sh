#!/usr/bin/env bash
# Installs wasm-bindgen-cli (wasm-bindgen, wasm-bindgen-test-runner), pinned to the wasm-bindgen
# version in Cargo.lock, into .tools/bin from crates.io. Idempotent: nothing to do when the right
# version is there. Used by scripts/setup.sh (in the background while apt, pip and npm
# download), scripts/setup-extra.sh and scripts/build-web.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
want=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/version = |"/, ""); print; exit}' Cargo.lock)
have=$(.tools/bin/wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)
if [ "$have" != "$want" ]; then
  echo "install-wasm-bindgen: cargo install --debug wasm-bindgen-cli $want into .tools (about 3 minutes)"
  # Not --locked: the CLI's lock file pins a webpki-roots the registry no longer has.
  # --debug: an unoptimised build installs in 177 s instead of 376 s here, and its output is
  # byte for byte the same; it runs 3.1 s instead of 0.9 s on the threaded page's module.
  # Its own target dir, not a CARGO_TARGET_DIR from the environment, whose lock a build of the
  # workspace beside it may hold.
  CARGO_TARGET_DIR="$PWD/.tools/target" cargo install --quiet --debug --root .tools \
    wasm-bindgen-cli --version "$want"
  rm -rf .tools/target
fi
