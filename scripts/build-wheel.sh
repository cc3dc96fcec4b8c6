#!/usr/bin/env bash
# Builds the Python package `sfmeval` (crates/sfmeval-py: PyO3 bindings of the core, abi3 for
# CPython >= 3.9) as a wheel into target/wheels/ with maturin, in the release profile the tests
# use (no LTO, 16 codegen units, as scripts/build-release.sh), so the core compiled for the CLI is
# reused. Install with `pip install target/wheels/sfmeval-*.whl`.
# MATURIN: the maturin to run (default: maturin on PATH, else .venv/bin/maturin).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_PROFILE_RELEASE_LTO="${CARGO_PROFILE_RELEASE_LTO:-false}"
export CARGO_PROFILE_RELEASE_CODEGEN_UNITS="${CARGO_PROFILE_RELEASE_CODEGEN_UNITS:-16}"
maturin=${MATURIN:-$(command -v maturin || echo .venv/bin/maturin)}
[ -x "$maturin" ] || { echo "build-wheel: maturin not found (scripts/setup.sh installs it in .venv)" >&2; exit 1; }
# The interpreter maturin tags and checks the wheel with: any CPython >= 3.9 (the wheel is abi3).
python=${SFMEVAL_PYTHON:-$(command -v python3)}
rm -f target/wheels/sfmeval-*.whl
"$maturin" build --release --locked -m crates/sfmeval-py/Cargo.toml -i "$python" \
  --out target/wheels "$@"
ls target/wheels/sfmeval-*.whl
