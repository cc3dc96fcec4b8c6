#!/usr/bin/env bash
# Runs every test of sfmeval: formatting, lints, docs, the wasm32 build of the core, the Rust unit
# and integration tests, and the Python tests that compare sfmeval with independent tools (Open3D,
# trimesh, scipy, pycolmap, Blender), and the benchmark in quick mode. Prints a final "N passed, N failed" line.
# Needs scripts/setup.sh first.
set -uo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
passed=0; failed=0; failures=()
log=$(mktemp -d)

check() { # name, command...
  local name=$1; shift
  local t=$SECONDS
  if "$@" >"$log/$name.log" 2>&1; then
    passed=$((passed + 1)); echo "ok     $name ($((SECONDS - t)) s)"
  else
    failed=$((failed + 1)); failures+=("$name"); echo "FAILED $name ($((SECONDS - t)) s)"; tail -40 "$log/$name.log"
  fi
}

check fmt cargo fmt --all --check
check clippy cargo clippy --workspace --all-targets --locked -- -D warnings
check doc env RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
check wasm32-core cargo build -p sfmeval --target wasm32-unknown-unknown --release --locked
check bench-compiles cargo bench --workspace --no-run --locked
# Module import graphs without cycles (core and runner): every arrow points down.
check import-graph-core python3 scripts/import-graph.py crates/sfmeval/src
check import-graph-runner python3 scripts/import-graph.py native_runner/src

# Rust tests: count each test.
t=$SECONDS
cargo build --release --locked -p sfmeval-cli >"$log/build.log" 2>&1 || { failed=$((failed + 1)); failures+=("release build"); tail -40 "$log/build.log"; }
cargo test --workspace --release --locked >"$log/cargo-test.log" 2>&1
rc=$?
p=$(grep -Eo '^test result: .* ([0-9]+) passed' "$log/cargo-test.log" | grep -Eo '[0-9]+ passed' | awk '{s+=$1} END {print s+0}')
f=$(grep -Eo '[0-9]+ failed' "$log/cargo-test.log" | awk '{s+=$1} END {print s+0}')
passed=$((passed + p)); failed=$((failed + f))
if [ $rc -ne 0 ]; then
  [ "$f" -eq 0 ] && { failed=$((failed + 1)); }
  failures+=("cargo test"); grep -E "^(test .* FAILED|---- |error)" -A 15 "$log/cargo-test.log" | head -80
fi
echo "cargo test: $p passed, $f failed ($((SECONDS - t)) s)"

# The side-by-side benchmark in its quick mode (tiny data, one round): every installed anchor
# must run and agree with sfmeval, so bench/compare.py cannot rot.
check bench-compare-quick .venv/bin/python bench/compare.py --quick

# Python tests (reference tools, real files).
export SFMEVAL_BIN="$PWD/target/release/sfmeval"
pytest_dirs=()
for d in tests/python blender_scripts/tests native_runner/tests; do [ -d "$d" ] && pytest_dirs+=("$d"); done
if [ ${#pytest_dirs[@]} -gt 0 ]; then
  t=$SECONDS
  .venv/bin/python -m pytest -q -p no:cacheprovider "${pytest_dirs[@]}" >"$log/pytest.log" 2>&1
  rc=$?
  last=$(grep -E '^(=+ )?[0-9]+ (passed|failed)|(passed|failed|error)' "$log/pytest.log" | tail -1)
  p=$(echo "$last" | grep -Eo '[0-9]+ passed' | grep -Eo '[0-9]+' || echo 0)
  f=$(echo "$last" | grep -Eo '[0-9]+ (failed|error)' | grep -Eo '[0-9]+' | awk '{s+=$1} END {print s+0}')
  passed=$((passed + ${p:-0})); failed=$((failed + ${f:-0}))
  if [ $rc -ne 0 ] && [ $rc -ne 5 ]; then
    [ "${f:-0}" -eq 0 ] && failed=$((failed + 1))
    failures+=("pytest"); grep -E "^(FAILED|ERROR)|Error|assert" "$log/pytest.log" | head -60
  fi
  echo "pytest: ${p:-0} passed, ${f:-0} failed ($((SECONDS - t)) s)"
fi

# Extra suites (browser, runner) register themselves as scripts/test-*.sh printing "N passed, N failed".
for s in scripts/test-*.sh; do
  [ -x "$s" ] || continue
  t=$SECONDS
  out=$("$s" 2>&1); rc=$?
  echo "$out" | tail -30
  line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -1)
  p=$(echo "$line" | grep -Eo '^[0-9]+'); f=$(echo "$line" | grep -Eo '[0-9]+ failed' | grep -Eo '[0-9]+')
  passed=$((passed + ${p:-0})); failed=$((failed + ${f:-0}))
  if [ $rc -ne 0 ] && [ "${f:-0}" -eq 0 ]; then failed=$((failed + 1)); failures+=("$s"); fi
  echo "$s: ${p:-0} passed, ${f:-0} failed ($((SECONDS - t)) s)"
done

[ ${#failures[@]} -gt 0 ] && echo "failing: ${failures[*]}"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
