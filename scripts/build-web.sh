#!/usr/bin/env bash
# Builds the WebAssembly core once and assembles from it:
#   target/web/npm/            the npm package `sfmeval` (ESM + TypeScript declarations)
#   target/web/sfmeval-*.tgz   that package packed by `npm pack`
#   target/web/site/           the static page (www/ + the package + vendored three.js/uPlot + demo),
#                              with the threaded build in site/sfmeval-mt/
#   target/web/pkg-mt/         the threaded + SIMD128 build (for the page only)
# Downloads nothing at build time once scripts/setup-extra.sh (or a first run) has installed
# wasm-bindgen-cli (pinned to Cargo.lock's wasm-bindgen) into .tools/ and the npm dev packages.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/web
export PATH="$ROOT/.tools/bin:$PATH"
TARGET_DIR=${CARGO_TARGET_DIR:-$ROOT/target}
# the wasm is built as shipped: the manifest's release profile (scripts/test.sh overrides it for
# its native build only)
unset CARGO_PROFILE_RELEASE_LTO CARGO_PROFILE_RELEASE_CODEGEN_UNITS
t0=$SECONDS

scripts/install-wasm-bindgen.sh # nothing to do after scripts/setup.sh
for d in www crates/sfmeval-wasm/js; do
  [ -d "$d/node_modules" ] || (cd "$d" && npm ci --no-audit --no-fund --silent)
done

echo "build-web: cargo build (wasm32, release)"
# its own target dir (as the threaded build below): a native build beside it (scripts/test.sh
# runs the tests while this builds) does not wait for the lock of target/release, where a
# cross build keeps its build scripts and proc macros
CARGO_TARGET_DIR=$TARGET_DIR/wasm cargo build --release --locked --target wasm32-unknown-unknown -p sfmeval-wasm
raw_wasm=$TARGET_DIR/wasm/wasm32-unknown-unknown/release/sfmeval_wasm.wasm

mkdir -p "$OUT"
# wasm-bindgen, then wasm-opt -O3 (~20 s; skipped when wasm-bindgen's output did not change).
# Usage: bindgen RAW_WASM OUT_DIR [wasm-opt feature flags...]
bindgen() {
  local raw=$1 dir=$2 hash; shift 2
  rm -rf "$dir.tmp"
  wasm-bindgen --target web --out-dir "$dir.tmp" "$raw"
  hash=$(sha256sum "$dir.tmp/sfmeval_wasm_bg.wasm" | cut -d' ' -f1)
  if [ -f "$dir/.source-hash" ] && [ "$(cat "$dir/.source-hash")" = "$hash" ]; then
    cp "$dir/sfmeval_wasm_bg.wasm" "$dir.tmp/sfmeval_wasm_bg.wasm"
  else
    echo "build-web: wasm-opt -O3 $*"
    crates/sfmeval-wasm/js/node_modules/.bin/wasm-opt -O3 "$@" "$dir.tmp/sfmeval_wasm_bg.wasm" -o "$dir.tmp/opt.wasm"
    mv "$dir.tmp/opt.wasm" "$dir.tmp/sfmeval_wasm_bg.wasm"
  fi
  echo "$hash" > "$dir.tmp/.source-hash"
  rm -rf "$dir" && mv "$dir.tmp" "$dir"
}
bindgen "$raw_wasm" "$OUT/pkg"

# The threaded build, which the page loads where it is cross-origin isolated and has SIMD: the
# core's rayon maps on a pool of Web Workers (wasm-bindgen-rayon) over shared memory, compiled
# with SIMD128. Threads need std rebuilt with atomics: -Z build-std on the stable toolchain
# (RUSTC_BOOTSTRAP=1; rust-src comes from scripts/setup.sh), in its own target dir so that the
# two builds' flags do not invalidate each other. SFMEVAL_THREADS=0 skips it (the page then runs
# its single-thread build everywhere).
if [ "${SFMEVAL_THREADS:-1}" != 0 ]; then
  if ! rustup component list --installed 2>/dev/null | grep -q '^rust-src'; then
    echo "build-web: rustup component add rust-src (for -Z build-std; scripts/setup.sh does this)"
    rustup component add rust-src
  fi
  echo "build-web: cargo build (wasm32, threads + SIMD128, release)"
  mt_target=$TARGET_DIR/wasm-threads
  # the link of the final module only: shared memory (imported, so every worker gets the same
  # one; up to 4 GB) and the TLS exports wasm-bindgen's thread start-up calls
  RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR=$mt_target \
    RUSTFLAGS="-C target-feature=+atomics,+bulk-memory,+mutable-globals,+simd128 -C link-arg=--max-memory=4294967296" \
    cargo rustc --release --locked --target wasm32-unknown-unknown -Z build-std=panic_abort,std \
    -p sfmeval-wasm --features threads --lib --crate-type cdylib -- \
    -C link-arg=--shared-memory -C link-arg=--import-memory -C link-arg=--export=__wasm_init_tls \
    -C link-arg=--export=__tls_size -C link-arg=--export=__tls_align -C link-arg=--export=__tls_base
  bindgen "$mt_target/wasm32-unknown-unknown/release/sfmeval_wasm.wasm" "$OUT/pkg-mt" \
    --enable-threads --enable-bulk-memory --enable-mutable-globals --enable-simd --enable-sign-ext \
    --enable-nontrapping-float-to-int --enable-reference-types --enable-multivalue
else
  rm -rf "$OUT/pkg-mt"
fi

# npm package
rm -rf "$OUT/npm" && mkdir -p "$OUT/npm"
cp crates/sfmeval-wasm/js/{package.json,index.js,index.d.ts,report.d.ts,dtu-report.d.ts,poses-report.d.ts,eth3d-report.d.ts,tnt-report.d.ts,README.md} "$OUT/npm/"
cp "$OUT"/pkg/sfmeval_wasm{.js,.d.ts,_bg.wasm,_bg.wasm.d.ts} "$OUT/npm/"
rm -f "$OUT"/sfmeval-*.tgz
(cd "$OUT/npm" && npm pack --silent --pack-destination "$OUT" >/dev/null)

# static page
SITE=$OUT/site
rm -rf "$SITE" && mkdir -p "$SITE/sfmeval" "$SITE/vendor/three/addons/controls" "$SITE/vendor/uplot" "$SITE/demo"
cp www/*.html www/*.js www/*.css "$SITE/"
cp "$OUT"/npm/*.js "$OUT"/npm/*.wasm "$SITE/sfmeval/"
if [ -d "$OUT/pkg-mt" ]; then # the threaded build behind the same API (www/worker.js picks one)
  mkdir -p "$SITE/sfmeval-mt"
  cp crates/sfmeval-wasm/js/index.js "$SITE/sfmeval-mt/"
  cp -r "$OUT"/pkg-mt/sfmeval_wasm.js "$OUT"/pkg-mt/sfmeval_wasm_bg.wasm "$OUT"/pkg-mt/snippets "$SITE/sfmeval-mt/"
fi
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
mt=$OUT/pkg-mt/sfmeval_wasm_bg.wasm
[ -f "$mt" ] && mt_size="; threaded $(stat -c %s "$mt") bytes, $(gzip -9c "$mt" | wc -c) gzipped" || mt_size="; no threaded build"
echo "build-web: wasm $(stat -c %s "$wasm") bytes, $(gzip -9c "$wasm" | wc -c) gzipped$mt_size; package $(ls "$OUT"/sfmeval-*.tgz); site $SITE ($((SECONDS - t0)) s)"
