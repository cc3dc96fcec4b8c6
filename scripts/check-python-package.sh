#!/usr/bin/env bash
# The Python package as a user gets it: builds the wheel (scripts/build-wheel.sh), installs it
# with numpy and pytest in a fresh venv (not editable, not the source tree) and runs
# crates/sfmeval-py/tests there against the CLI (SFMEVAL_BIN, default target/release/sfmeval,
# which must be built). Then mypy --strict on the typed examples (crates/sfmeval-py/examples/),
# which run against the wheel; matplotlib (an optional dependency of an example, not of the
# package) is installed in the venv so that the histogram example saves its figure.
# A skipped test fails this check: it would have tested nothing.
# PYTHON: the interpreter of the fresh venv (default python3; any CPython >= 3.9).
set -euo pipefail
cd "$(dirname "$0")/.."
t0=$SECONDS
MATURIN=${MATURIN:-.venv/bin/maturin} scripts/build-wheel.sh
echo "check-python-package: wheel built in $((SECONDS - t0)) s"
venv=$(mktemp -d)/venv
trap 'rm -rf "$(dirname "$venv")"' EXIT
"${PYTHON:-python3}" -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check target/wheels/sfmeval-*.whl numpy pytest \
  matplotlib
export SFMEVAL_BIN=${SFMEVAL_BIN:-$PWD/target/release/sfmeval}
# from a folder outside the repository: `import sfmeval` can only find the installed wheel
(cd "$(dirname "$venv")" && "$venv/bin/python" -m pytest -q -rs -p no:cacheprovider \
  "$OLDPWD/crates/sfmeval-py/tests") | tee "$(dirname "$venv")/pytest.log"
if grep -Eq '[0-9]+ (skipped|xfailed)' "$(dirname "$venv")/pytest.log"; then
  echo "check-python-package: skipped tests count as failures"; exit 1
fi
if [ -d crates/sfmeval-py/examples ]; then
  mypy=${MYPY:-.venv/bin/mypy}
  MYPYPATH= "$mypy" --strict --python-executable "$venv/bin/python" crates/sfmeval-py/examples
  figure=$(dirname "$venv")/histogram.png
  for example in crates/sfmeval-py/examples/*.py; do
    "$venv/bin/python" "$example" . "$figure" >/dev/null
  done
  [ -s "$figure" ] || { echo "check-python-package: the example saved no histogram"; exit 1; }
fi
echo "check-python-package: done in $((SECONDS - t0)) s"
