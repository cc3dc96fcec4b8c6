#!/usr/bin/env bash
# Runs every test of sfmeval: formatting, lints, docs, the Rust unit and integration tests, the
# benchmarks in quick mode, the Python tests that compare sfmeval with independent tools (Open3D,
# trimesh, scipy, pycolmap, Blender) and, in the background beside them, the page's wasm builds and
# the extra suites (scripts/test-*.sh: browser and npm). Prints a final "N passed, N failed" line.
# Needs scripts/setup.sh first.
#
# Skipped tests (a pytest skip, an ignored Rust test, a "skipped: ..." line of a suite, an anchor
# of the benchmark that is not installed) are listed with their reasons and counted. Under
# CI=true or CI=1 (.ci/run sets it) every skip counts as a failure: a test skipped because a
# tool is missing has tested nothing, and a broken install must not pass.
set -uo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
# The native release build the tests run: without LTO, 16 codegen units (a fresh build of every
# binary, example and test took 479 s instead of 657 s here: thin LTO relinked the whole core into
# each of the ten test and example binaries). Same code, same results: the Python and browser
# tests compare its reports with the wasm build's (built as shipped, scripts/build-web.sh) byte for
# byte. Benchmarks and users build with the manifest's profile. Set either variable to override.
export CARGO_PROFILE_RELEASE_LTO="${CARGO_PROFILE_RELEASE_LTO:-false}"
export CARGO_PROFILE_RELEASE_CODEGEN_UNITS="${CARGO_PROFILE_RELEASE_CODEGEN_UNITS:-16}"
passed=0; failed=0; skipped=0; failures=(); skips=()
log=$(mktemp -d)
ci=false; case "${CI:-}" in true | 1) ci=true ;; esac

skip() { # what, why: one skipped test or suite
  skipped=$((skipped + 1)); skips+=("$1: $2"); echo "SKIPPED $1: $2"
}

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
# --all-targets: the benches and examples type-check too (bench/compare.py below builds and runs
# bench_op; a full `cargo bench --no-run` cost 400+ s of release builds for no further check).
check clippy cargo clippy --workspace --all-targets --locked -- -D warnings
check doc env RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
# The core's feature `ts` (ts-rs derives on the report types, off in every build above): lints,
# and the npm package's report.d.ts is what the types generate (a debug build of the core alone).
check clippy-ts cargo clippy -p sfmeval --all-targets --features ts --locked -- -D warnings
check report-types scripts/gen-report-types.sh --check
# Module import graphs without cycles (core and runner): every arrow points down.
check import-graph-core python3 scripts/import-graph.py crates/sfmeval/src
check import-graph-runner python3 scripts/import-graph.py native_runner/src

# Rust tests: count each test.
t=$SECONDS
# Every binary and example once (scripts/build-release.sh: the features `cargo test` resolves too,
# and the one release build command of the Python tests, bench/compare.py and test-browser.sh).
scripts/build-release.sh >"$log/build.log" 2>&1 || { failed=$((failed + 1)); failures+=("release build"); tail -40 "$log/build.log"; }
# From here on, in the background: the page's wasm builds (scripts/build-web.sh, niced: they take
# what the tests leave of the two cores), then the extra suites. Extra suites (browser, runner)
# register themselves as scripts/test-*.sh printing "N passed, N failed" (and "skipped: WHAT: WHY"
# per skipped test, if any); a suite that is not executable, ends without that line or runs nothing
# has not tested anything. pytest keeps only 1.2-1.5 of the two cores busy (Blender, the SfM tools,
# Slurm's scheduling and time limits wait on each other); the results are read after it.
suites=()
for s in scripts/test-*.sh; do
  [ -e "$s" ] || continue
  [ -x "$s" ] || { skip "$s" "not executable"; continue; }
  suites+=("$s")
done
suite_start=$SECONDS
(
  nice -n 19 scripts/build-web.sh >"$log/build-web.log" 2>&1
  echo "build-web (background, niced): exit $?, $((SECONDS - suite_start)) s" >"$log/build-web.sum"
  for k in "${!suites[@]}"; do
    "${suites[$k]}" >"$log/suite-$k.out" 2>&1
    echo $? >"$log/suite-$k.rc"
  done
) &
background=$!
cargo test --workspace --release --locked >"$log/cargo-test.log" 2>&1
rc=$?
p=$(grep -Eo '^test result: .* ([0-9]+) passed' "$log/cargo-test.log" | grep -Eo '[0-9]+ passed' | awk '{s+=$1} END {print s+0}')
f=$(grep -Eo '[0-9]+ failed' "$log/cargo-test.log" | awk '{s+=$1} END {print s+0}')
passed=$((passed + p)); failed=$((failed + f))
if [ $rc -ne 0 ]; then
  [ "$f" -eq 0 ] && { failed=$((failed + 1)); }
  failures+=("cargo test"); grep -E "^(test .* FAILED|---- |error)" -A 15 "$log/cargo-test.log" | head -80
fi
# #[ignore]d tests: "test NAME ... ignored[, reason]"
while read -r name why; do skip "cargo test $name" "${why:-ignored}"; done < <(
  sed -nE 's/^test (.+) \.\.\. ignored(, (.*))?$/\1 \3/p' "$log/cargo-test.log")
[ "$p" -gt 0 ] || { failed=$((failed + 1)); failures+=("cargo test ran no test"); }
echo "cargo test: $p passed, $f failed ($((SECONDS - t)) s)"

# The side-by-side benchmark in its quick mode (tiny data, one round): every installed anchor
# must run and agree with sfmeval, so bench/compare.py cannot rot.
check bench-compare-quick .venv/bin/python bench/compare.py --quick
# an anchor that is not installed is left out of the comparison: a skip
while read -r line; do skip "bench-compare-quick" "$line"; done < <(
  sed -nE 's/^skipped: (.*)$/\1/p' "$log/bench-compare-quick.log")

# The per-stage wall and CPU table at 1 and 2 threads, quick mode (bench_op's CPU clock and the
# thread counts' reports compared).
check bench-stages-quick .venv/bin/python bench/stages.py --quick

# The Tanks and Temples protocol against the benchmark's own toolbox, quick mode.
check bench-tnt-quick .venv/bin/python bench/tanksandtemples.py --quick

# The DTU evaluation against its Python port, quick mode (about 10 s).
check bench-dtu-quick .venv/bin/python bench/dtu.py --quick

# ETH3D's evaluation against its official C++ tool (built once by scripts/build-eth3d-tool.sh),
# quick mode (about 10 s).
check bench-eth3d-quick .venv/bin/python bench/eth3d.py --quick

# The pose protocols (COLMAP's benchmark, IMC's mAA, CO3D's RRA/RTA) against their official code
# (tests/third_party/), quick mode: 60 images, one round, the numbers must agree (a few seconds).
check bench-poses-quick .venv/bin/python bench/poses.py --quick

# The Python package (crates/sfmeval-py): its wheel built, installed in a fresh venv and tested
# against the CLI's reports byte for byte.
check python-package scripts/check-python-package.sh

# Python tests (reference tools, real files).
export SFMEVAL_BIN="$PWD/target/release/sfmeval" SFMEVAL_RUNNER_BIN="$PWD/target/release/sfmeval-runner"
pytest_dirs=()
for d in tests/python blender_scripts/tests native_runner/tests; do [ -d "$d" ] && pytest_dirs+=("$d"); done
if [ ${#pytest_dirs[@]} -gt 0 ]; then
  t=$SECONDS
  # -rfEs: failures, errors and skip reasons in the log; the JUnit file gives every test's
  # outcome, skips with their reasons.
  .venv/bin/python -m pytest -q -rfEs -p no:cacheprovider -o junit_family=xunit1 \
    --junitxml="$log/pytest.xml" "${pytest_dirs[@]}" >"$log/pytest.log" 2>&1
  rc=$?
  # "passed failed skipped", then one "test<TAB>reason" line per skipped test
  python3 - "$log/pytest.xml" >"$log/pytest.sum" 2>&1 <<'PY'
import sys
import xml.etree.ElementTree as ET

p = f = 0
skips = []
for case in ET.parse(sys.argv[1]).getroot().iter("testcase"):
    name = f"{case.get('file') or case.get('classname')}::{case.get('name')}"
    if case.find("failure") is not None or case.find("error") is not None:
        f += 1
    elif (s := case.find("skipped")) is not None:
        skips.append(f"{name}\t{' '.join((s.get('message') or s.get('type') or '').split())}")
    else:
        p += 1
print(p, f, len(skips))
for line in skips:
    print(line)
PY
  if read -r p f s <"$log/pytest.sum" 2>/dev/null && [[ "$p $f $s" =~ ^[0-9]+\ [0-9]+\ [0-9]+$ ]]; then
    passed=$((passed + p)); failed=$((failed + f))
    while IFS=$'\t' read -r name why; do skip "$name" "$why"; done < <(tail -n +2 "$log/pytest.sum")
    # pytest's own summary line ("... 3 skipped ... in 12.3s") must say the same (JUnit
    # reports an xfail as a skip too)
    said=$(grep -E '^=* ?[0-9]+ [a-z]+.* in [0-9.]+s' "$log/pytest.log" | tail -1 |
      grep -Eo '[0-9]+ (skipped|xfailed)' | awk '{s+=$1} END {print s+0}')
    if [ "$said" -ne "$s" ]; then
      echo "pytest: its summary says $said skipped, the JUnit file $s"
      failed=$((failed + 1)); failures+=("pytest skip count")
    fi
  else
    p=0 f=0 s=0; cat "$log/pytest.sum"
  fi
  # rc 0 = all passed (skips allowed), 1 = failures, anything else (5: no test collected, an
  # internal or usage error, a crash) is a failure of the run itself
  if [ $rc -ne 0 ] || [ "$p" -eq 0 ]; then
    [ "$f" -eq 0 ] && failed=$((failed + 1))
    failures+=("pytest"); grep -E "^(FAILED|ERROR)|Error|assert" "$log/pytest.log" | head -60
    [ "$f" -eq 0 ] && tail -20 "$log/pytest.log"
  fi
  echo "pytest: $p passed, $f failed, $s skipped ($((SECONDS - t)) s)"
fi

# The extra suites' results.
wait "$background"
cat "$log/build-web.sum" 2>/dev/null
for k in "${!suites[@]}"; do
  s=${suites[$k]}
  rc=$(cat "$log/suite-$k.rc" 2>/dev/null || echo 1)
  out=$(cat "$log/suite-$k.out" 2>/dev/null)
  echo "$out" | tail -30
  line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -1)
  p=$(echo "$line" | grep -Eo '^[0-9]+'); f=$(echo "$line" | grep -Eo '[0-9]+ failed' | grep -Eo '[0-9]+')
  passed=$((passed + ${p:-0})); failed=$((failed + ${f:-0}))
  while read -r why; do skip "$s" "$why"; done < <(echo "$out" | sed -nE 's/^skipped: (.*)$/\1/p')
  if [ -z "$line" ] || [ "${p:-0}" -eq 0 ] || { [ $rc -ne 0 ] && [ "${f:-0}" -eq 0 ]; }; then
    failed=$((failed + 1)); failures+=("$s")
  elif [ "${f:-0}" -gt 0 ]; then
    failures+=("$s")
  fi
  echo "$s: ${p:-0} passed, ${f:-0} failed (the background's wasm builds and suites done $((SECONDS - suite_start)) s after they started)"
done

if [ "$skipped" -gt 0 ]; then
  echo "skipped ($skipped):"; printf '  %s\n' "${skips[@]}"
  if $ci; then
    echo "CI=true: the $skipped skipped test(s) count as failed"
    failed=$((failed + skipped)); failures+=("$skipped skipped")
  else
    echo "(not counted outside CI; CI=true counts them as failed)"
  fi
fi
[ ${#failures[@]} -gt 0 ] && echo "failing: ${failures[*]}"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
