#!/usr/bin/env bash
# Tests of the browser page and the npm package: builds the wasm once (scripts/build-web.sh),
# then runs the wasm-bindgen tests (Node and headless Chromium), the packed npm tarball in Node
# and in a bundler-free page in Chromium (report byte for byte the CLI's; the README's examples run
# as written, its TypeScript types checked by tsc: npm-test.mjs, npm-browser.mjs), every alignment path
# through the npm package in Node against the CLI (byte for byte), and the page end to end in
# Chromium via playwright-core, served with the COOP/COEP headers so that it runs its threaded build
# (tests/browser/e2e.mjs: results equal the CLI's; tests/browser/threads.mjs: the threaded build's
# reports equal the CLI's, and without the headers the single-thread fallback; tests/browser/dense.mjs:
# a dense PLY streamed into the page, a too-large one refused; tests/browser/ux.mjs:
# layout at 1366×768 and 1920×1080, errors in view, keyboard, axe-core, cancel; tests/browser/compare.mjs:
# a runner runs folder compared in the page equals `sfmeval-runner report`'s table and reports;
# tests/browser/dtu.mjs: the DTU evaluation in npm and in the page equals `sfmeval dtu`; likewise
# tests/browser/poses.mjs, eth3d.mjs and tnt.mjs for `sfmeval poses`, `sfmeval eth3d` and `sfmeval tnt`).
# SFMEVAL_BENCH=1 also runs the speed benchmarks (bench/data; not tests): whole eval in the page
# with threads off and on against native with 1 and 2 threads (tests/browser/bench.mjs), and per
# operation in Node (tests/browser/bench-ops.mjs).
# Ends with "N passed, N failed".
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
export PATH="$ROOT/.tools/bin:$PATH" CARGO_TERM_COLOR=never
passed=0; failed=0
log=$(mktemp -d)
out=$ROOT/target/web/test-output
mkdir -p "$out"

fail() { failed=$((failed + 1)); echo "FAILED $1"; tail -30 "$2"; }
count() { # name, file with ok / FAILED lines, exit code of the driver that wrote it
  local p f
  p=$(grep -c '^ok ' "$2"); f=$(grep -c '^FAILED ' "$2")
  passed=$((passed + p)); failed=$((failed + f))
  grep -E '^(FAILED|page:|npm:|bench|note:)' "$2"
  # a driver that crashed, or ended without running a check, tested nothing
  if [ "$3" -ne 0 ] && [ "$f" -eq 0 ]; then fail "$1 (exit $3)" "$2"
  elif [ "$p" -eq 0 ] && [ "$f" -eq 0 ]; then fail "$1: no check ran" "$2"; fi
}

t=$SECONDS
if ! scripts/build-web.sh >"$log/build.log" 2>&1; then
  fail "build-web" "$log/build.log"; echo "$passed passed, $failed failed"; exit 1
fi
tail -1 "$log/build.log"
scripts/build-release.sh >"$log/cli.log" 2>&1 || fail "cli build" "$log/cli.log"
echo "build: $((SECONDS - t)) s"
(cd tests/browser && [ -f node_modules/axe-core/axe.min.js ] && [ -f node_modules/typescript/bin/tsc ] ||
  npm ci --no-audit --no-fund --silent)

# wasm-bindgen-test: one build (cargo runs it in Node), then the same test module in headless
# Chromium through the runner directly.
t=$SECONDS
wbt() { # where, log, command...
  local where=$1 logf=$2; shift 2
  "$@" >"$logf" 2>&1
  local rc=$? p f
  p=$(grep -Eo 'test result: .* ([0-9]+) passed' "$logf" | grep -Eo '[0-9]+ passed' | awk '{s+=$1} END {print s+0}')
  f=$(grep -Eo '[0-9]+ failed' "$logf" | awk '{s+=$1} END {print s+0}')
  passed=$((passed + p)); failed=$((failed + f))
  if [ $rc -ne 0 ] && [ "$f" -eq 0 ]; then fail "wasm-bindgen-test ($where)" "$logf"
  elif [ "$p" -eq 0 ] && [ "$f" -eq 0 ]; then fail "wasm-bindgen-test ($where): no test ran" "$logf"; fi
  # #[ignore]d tests are skips (scripts/test.sh lists them; CI=true fails on them)
  sed -nE "s/^test (.+) \.\.\. ignored.*$/skipped: wasm-bindgen-test ($where) \1: ignored/p" "$logf"
  echo "wasm-bindgen-test ($where): $p passed, $f failed"
}
# (the wasm32 profile and target dir of scripts/build-web.sh, so that its dependencies are reused)
wasm_target=${CARGO_TARGET_DIR:-$ROOT/target}/wasm
wbt node "$log/wbt-node.log" env -u CARGO_PROFILE_RELEASE_LTO -u CARGO_PROFILE_RELEASE_CODEGEN_UNITS \
  CARGO_TARGET_DIR="$wasm_target" CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner \
  cargo test --release --locked --target wasm32-unknown-unknown -p sfmeval-wasm --test web
test_wasm=$(ls -t "$wasm_target"/wasm32-unknown-unknown/release/deps/web-*.wasm 2>/dev/null | head -1)
if [ -n "$test_wasm" ]; then
  wbt chromium "$log/wbt-chromium.log" env WASM_BINDGEN_USE_BROWSER=1 CHROMEDRIVER=/usr/bin/chromedriver \
    wasm-bindgen-test-runner "$test_wasm"
else
  fail "wasm-bindgen-test (chromium): no test module" "$log/wbt-node.log"
fi
echo "wasm-bindgen-test: $((SECONDS - t)) s"

# npm tarball in Node
t=$SECONDS
./target/release/sfmeval eval --gt data/demo/ground_truth.glb --recon data/demo/sparse \
  --gt-cameras data/demo/cameras.json --quiet --report "$out/cli-demo.json"
node tests/browser/npm-test.mjs target/web/sfmeval-*.tgz "$out/cli-demo.json" >"$log/npm.log" 2>&1
count npm-test "$log/npm.log" $?
rm -rf "$out/demo-depth"
.venv/bin/python tests/browser/make_demo_depth.py "$out/demo-depth" >"$log/depth.log" 2>&1 || fail "make_demo_depth" "$log/depth.log"
node tests/browser/same-everywhere.mjs target/web/npm target/release/sfmeval "$out" "$out/demo-depth" >"$log/same.log" 2>&1
count same-everywhere "$log/same.log" $?
node tests/browser/npm-browser.mjs target/web/sfmeval-*.tgz "$out/cli-demo.json" "$out" >"$log/npm-browser.log" 2>&1
count npm-browser "$log/npm-browser.log" $?
echo "npm: $((SECONDS - t)) s"

# the page in Chromium
t=$SECONDS
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
# served as a static host must serve it: with COOP/COEP (cross-origin isolated, so threaded);
# a second server without them for the single-thread fallback (tests/browser/threads.mjs)
python3 scripts/serve_site.py "$port" --directory target/web/site >"$log/http.log" 2>&1 &
server=$!
plain_port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 scripts/serve_site.py "$plain_port" --no-isolation --directory target/web/site >"$log/http-plain.log" 2>&1 &
plain_server=$!
trap 'kill $server $plain_server 2>/dev/null' EXIT
for p in "$port" "$plain_port"; do
  for _ in $(seq 50); do curl -sf "http://127.0.0.1:$p/" >/dev/null && break; sleep 0.1; done
done
node tests/browser/e2e.mjs --url "http://127.0.0.1:$port/" --cli target/release/sfmeval --out "$out" >"$log/e2e.log" 2>&1
count e2e "$log/e2e.log" $?
echo "e2e: $((SECONDS - t)) s (screenshots in $out)"
# the threaded build where the page is isolated (reports byte for byte the CLI's), the
# single-thread fallback with its note where it is not
t=$SECONDS
node tests/browser/threads.mjs --url "http://127.0.0.1:$port/" --plain-url "http://127.0.0.1:$plain_port/" \
  --cli target/release/sfmeval --out "$out" --depth "$out/demo-depth" >"$log/threads.log" 2>&1
count threads "$log/threads.log" $?
echo "threads: $((SECONDS - t)) s"
# the page as a person uses it: layout at two window sizes, errors, keyboard, axe-core, cancel
t=$SECONDS
node tests/browser/ux.mjs --url "http://127.0.0.1:$port/" --out "$out" >"$log/ux.log" 2>&1
count ux "$log/ux.log" $?
echo "ux: $((SECONDS - t)) s (screenshots ux-*.png in $out)"
# a dense binary PLY streamed into the page (2.5M points here, past the viewer's 2M drawn-point cap;
# SFMEVAL_DENSE_POINTS for more), and
# a 40M-point file refused from its header (tests/browser/dense.mjs)
t=$SECONDS
node tests/browser/dense.mjs --url "http://127.0.0.1:$port/" --cli target/release/sfmeval --out "$out/dense" \
  --points "${SFMEVAL_DENSE_POINTS:-2500000}" >"$log/dense.log" 2>&1
count dense "$log/dense.log" $?
rm -f "$out"/dense/*.ply
echo "dense: $((SECONDS - t)) s"

# Compare: a runner runs folder of four pipelines (custom commands that copy the demo's COLMAP
# model and two real sparse clouds of the same statue from tests/fixtures/global, and one that
# fails) on a dataset
# made of the demo's ground truth and cameras; the page's table, its exports and every report
# must equal what `sfmeval-runner report` writes for that folder (tests/browser/compare.mjs).
t=$SECONDS
cmp=$out/compare-runs
rm -rf "$cmp" && mkdir -p "$cmp/statue/images"
cp data/demo/ground_truth.glb data/demo/cameras.json "$cmp/statue/"
# the custom commands never read the images: empty files give the dataset its 36 image names
for i in $(seq -f %04g 0 35); do : > "$cmp/statue/images/$i.jpg"; done
fx=$ROOT/tests/fixtures/global
if scripts/build-release.sh >"$log/runner.log" 2>&1 &&
  ./target/release/sfmeval-runner run --datasets "$cmp/statue" --intrinsics known --out "$cmp/runs" \
    --pipelines 'sparse-colmap;pycolmap-ply;theia-ply;broken' --custom "broken=exit 3; {out}" \
    --custom "sparse-colmap=cp '$ROOT/data/demo/sparse/'*.txt {out}/" \
    --custom "pycolmap-ply=cp '$fx/pycolmap_points3D.ply' {out}/" \
    --custom "theia-ply=cp '$fx/theia_points.ply' {out}/" >>"$log/runner.log" 2>&1 &&
  ./target/release/sfmeval-runner report "$cmp/runs" --out "$cmp/table" >>"$log/runner.log" 2>&1 &&
  printf '{"schema": "sfmeval.crop/1", "volume": {"kind": "sphere", "center": [0, 0.1, 0], "radius": 0.45}, "max_distance": 0.02}\n' >"$cmp/crop.json" &&
  ./target/release/sfmeval-runner report "$cmp/runs" --crop "$cmp/crop.json" --out "$cmp/table-crop" >>"$log/runner.log" 2>&1; then
  node tests/browser/compare.mjs --url "http://127.0.0.1:$port/" --runs "$cmp/runs" --dataset "$cmp/statue" \
    --table "$cmp/table" --cli target/release/sfmeval --out "$out" \
    --crop "$cmp/crop.json" --table-crop "$cmp/table-crop" >"$log/compare.log" 2>&1
  count compare "$log/compare.log" $?
else
  fail "compare: making the runs folder" "$log/runner.log"
fi
echo "compare: $((SECONDS - t)) s (screenshots compare*.png in $out)"

# DTU: a scan in DTU's layout (tests/python/dtu_scene.py, a small dense cloud), evaluated by the npm
# package in Node and by the page's section 6 in Chromium: report, summary and error clouds equal
# `sfmeval dtu`'s (tests/browser/dtu.mjs)
t=$SECONDS
rm -rf "$out/dtu-scene"
if .venv/bin/python -c "import sys, pathlib; sys.path.insert(0, 'tests/python'); import dtu_scene; dtu_scene.build(pathlib.Path(sys.argv[1]), sys.argv[2], dense_points=20000)" \
  "$out/dtu-scene" "$ROOT/target/release/sfmeval" >"$log/dtu-scene.log" 2>&1; then
  node tests/browser/dtu.mjs --npm target/web/npm --cli target/release/sfmeval --scene "$out/dtu-scene" --out "$out" \
    --url "http://127.0.0.1:$port/" >"$log/dtu.log" 2>&1
  count dtu "$log/dtu.log" $?
else
  fail "dtu: making the scan" "$log/dtu-scene.log"
fi
echo "dtu: $((SECONDS - t)) s (screenshots dtu-*.png in $out)"

# The pose protocols: real SfM models (tests/fixtures/models, tests/fixtures/global) evaluated by the
# npm package in Node and by the page's section 7 in Chromium: report, summary and pairs CSV equal
# `sfmeval poses`'s (tests/browser/poses.mjs)
t=$SECONDS
node tests/browser/poses.mjs --npm target/web/npm --cli target/release/sfmeval --out "$out" \
  --url "http://127.0.0.1:$port/" >"$log/poses.log" 2>&1
count poses "$log/poses.log" $?
echo "poses: $((SECONDS - t)) s (screenshots poses-*.png in $out)"

# ETH3D: a scene in ETH3D's layout (tests/python/eth3d_scene.py, small), evaluated by the npm package
# and by the page's section 8: report, summary and coloured clouds equal `sfmeval eth3d`'s
# (tests/browser/eth3d.mjs)
t=$SECONDS
rm -rf "$out/eth3d-scene"
if .venv/bin/python -c "import sys, pathlib; sys.path.insert(0, 'tests/python'); import eth3d_scene; eth3d_scene.build(pathlib.Path(sys.argv[1]), sys.argv[2], scan_points=30000, dense_points=20000)" \
  "$out/eth3d-scene" "$ROOT/target/release/sfmeval" >"$log/eth3d-scene.log" 2>&1; then
  node tests/browser/eth3d.mjs --npm target/web/npm --cli target/release/sfmeval --scene "$out/eth3d-scene" --out "$out" \
    --url "http://127.0.0.1:$port/" >"$log/eth3d.log" 2>&1
  count eth3d "$log/eth3d.log" $?
else
  fail "eth3d: making the scene" "$log/eth3d-scene.log"
fi
echo "eth3d: $((SECONDS - t)) s (screenshots eth3d-*.png in $out)"

# Tanks and Temples: a scene in the benchmark's layout (tests/python/tnt_scene.py, small) with the
# trajectory `sfmeval log` writes from the demo's model, evaluated by the npm package and by the
# page's section 9: report, summary and every output file equal `sfmeval tnt`'s (tests/browser/tnt.mjs)
t=$SECONDS
rm -rf "$out/tnt-scene"
if .venv/bin/python -c "import sys, pathlib; sys.path.insert(0, 'tests/python'); import tnt_scene; pathlib.Path(sys.argv[2]).write_text(str(tnt_scene.build(sys.argv[1], 30000, 20000)['tau']))" \
    "$out/tnt-scene" "$out/tnt-tau.txt" >"$log/tnt-scene.log" 2>&1 &&
  ./target/release/sfmeval log --model data/demo/sparse --images "$out/tnt-scene/recon/images.txt" \
    --out "$out/tnt-scene/recon/traj.log" >>"$log/tnt-scene.log" 2>&1; then
  node tests/browser/tnt.mjs --npm target/web/npm --cli target/release/sfmeval --scene "$out/tnt-scene" --tau "$(cat "$out/tnt-tau.txt")" \
    --out "$out" --url "http://127.0.0.1:$port/" >"$log/tnt.log" 2>&1
  count tnt "$log/tnt.log" $?
else
  fail "tnt: making the scene" "$log/tnt-scene.log"
fi
echo "tnt: $((SECONDS - t)) s (screenshots tnt-*.png in $out)"

if [ "${SFMEVAL_BENCH:-0}" = 1 ]; then
  node tests/browser/bench.mjs --url "http://127.0.0.1:$port/" --cli target/release/sfmeval 2>&1 | tee "$log/bench.log"
  # per operation, npm package in Node vs native with one thread (needs examples/bench_op)
  scripts/build-release.sh -q &&
    node tests/browser/bench-ops.mjs 2>&1 | tee "$log/bench-ops.log"
fi
kill $server $plain_server 2>/dev/null
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
