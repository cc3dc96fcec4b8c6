#!/usr/bin/env bash
# Builds the WebAssembly core once and assembles from it:
#   target/web/npm/            the npm package `sfmeval` (ESM + TypeScript declarations)
#   target/web/sfmeval-*.tgz   that package packed by `npm pack`
#   target/web/site/           the static page (www/ + the package + vendored three.js/uPlot + demo)
# Downloads nothing at build time once scripts/setup-extra.sh (or a first run) has installed
# wasm-bindgen-cli (pinned to Cargo.lock's wasm-bindgen) into .tools/ and the npm dev packages.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/web
export PATH="$ROOT/.tools/bin:$PATH"
TARGET_DIR=${CARGO_TARGET_DIR:-$ROOT/target}
t0=$SECONDS

wb_version=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/version = |"/, ""); print; exit}' Cargo.lock)
if [ "$(wasm-bindgen --version 2>/dev/null | awk '{print $2}')" != "$wb_version" ]; then
  echo "build-web: installing wasm-bindgen-cli $wb_version into .tools (takes a few minutes)"
  cargo install --root "$ROOT/.tools" wasm-bindgen-cli --version "$wb_version"
fi
for d in www crates/sfmeval-wasm/js; do
  [ -d "$d/node_modules" ] || (cd "$d" && npm ci --no-audit --no-fund --silent)
done

echo "build-web: cargo build (wasm32, release)"
cargo build --release --locked --target wasm32-unknown-unknown -p sfmeval-wasm
raw_wasm=$TARGET_DIR/wasm32-unknown-unknown/release/sfmeval_wasm.wasm

mkdir -p "$OUT"
rm -rf "$OUT/pkg.tmp"
wasm-bindgen --target web --out-dir "$OUT/pkg.tmp" "$raw_wasm"
# wasm-opt takes ~20 s: skip it when wasm-bindgen's output did not change.
hash=$(sha256sum "$OUT/pkg.tmp/sfmeval_wasm_bg.wasm" | cut -d' ' -f1)
if [ -f "$OUT/pkg/.source-hash" ] && [ "$(cat "$OUT/pkg/.source-hash")" = "$hash" ]; then
  cp "$OUT/pkg/sfmeval_wasm_bg.wasm" "$OUT/pkg.tmp/sfmeval_wasm_bg.wasm"
else
  echo "build-web: wasm-opt -O3"
  crates/sfmeval-wasm/js/node_modules/.bin/wasm-opt -O3 "$OUT/pkg.tmp/sfmeval_wasm_bg.wasm" -o "$OUT/pkg.tmp/opt.wasm"
  mv "$OUT/pkg.tmp/opt.wasm" "$OUT/pkg.tmp/sfmeval_wasm_bg.wasm"
fi
echo "$hash" > "$OUT/pkg.tmp/.source-hash"
rm -rf "$OUT/pkg" && mv "$OUT/pkg.tmp" "$OUT/pkg"

# npm package
rm -rf "$OUT/npm" && mkdir -p "$OUT/npm"
cp crates/sfmeval-wasm/js/{package.json,index.js,index.d.ts,README.md} "$OUT/npm/"
cp "$OUT"/pkg/sfmeval_wasm{.js,.d.ts,_bg.wasm,_bg.wasm.d.ts} "$OUT/npm/"
rm -f "$OUT"/sfmeval-*.tgz
(cd "$OUT/npm" && npm pack --silent --pack-destination "$OUT" >/dev/null)

# static page
SITE=$OUT/site
rm -rf "$SITE" && mkdir -p "$SITE/sfmeval" "$SITE/vendor/three/addons/controls" "$SITE/vendor/uplot" "$SITE/demo"
cp www/*.html www/*.js www/*.css "$SITE/"
cp "$OUT"/npm/*.js "$OUT"/npm/*.wasm "$SITE/sfmeval/"
three=www/node_modules/three
cp "$three/build/three.module.js" "$three/build/three.core.js" "$three/LICENSE" "$SITE/vendor/three/"
cp "$three/examples/jsm/controls/OrbitControls.js" "$three/examples/jsm/controls/TransformControls.js" \
  "$SITE/vendor/three/addons/controls/"
cp www/node_modules/uplot/dist/uPlot.esm.js www/node_modules/uplot/dist/uPlot.min.css www/node_modules/uplot/LICENSE \
  "$SITE/vendor/uplot/"
# The demo: data/demo as it is, described by data/demo/manifest.json;
# without one, the manifest lists the usual file names that are present.
(cd data/demo && find . -type f ! -name '*.py' -printf '%P\n') | while read -r f; do
  mkdir -p "$SITE/demo/$(dirname "$f")" && cp "data/demo/$f" "$SITE/demo/$f"
done
if [ ! -f "$SITE/demo/manifest.json" ]; then
  python3 - "$SITE/demo" > "$SITE/demo/manifest.json" <<'PY'
import json, os, sys
d = sys.argv[1]
names = ("ground_truth.glb", "ground_truth.gltf", "ground_truth.ply", "ground_truth.obj")
m = {"ground_truth": [f for f in names if os.path.exists(os.path.join(d, f))][:1]}
if os.path.isdir(os.path.join(d, "sparse")):
    m["reconstruction"] = sorted("sparse/" + f for f in os.listdir(os.path.join(d, "sparse")))
    m["reconstruction_name"] = "sparse"
else:
    m["reconstruction"] = ["sparse.ply"]
if os.path.exists(os.path.join(d, "cameras.json")):
    m["gt_cameras"] = "cameras.json"
if os.path.exists(os.path.join(d, "gt_from_recon.txt")):
    m["transform"] = "gt_from_recon.txt"
print(json.dumps(m, indent=2))
PY
fi

wasm=$OUT/pkg/sfmeval_wasm_bg.wasm
echo "build-web: wasm $(stat -c %s "$wasm") bytes, $(gzip -9c "$wasm" | wc -c) gzipped; package $(ls "$OUT"/sfmeval-*.tgz); site $SITE ($((SECONDS - t0)) s)"
