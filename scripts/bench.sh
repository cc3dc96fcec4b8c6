#!/usr/bin/env bash
# The side-by-side benchmark from a fresh clone, in one command: installs the anchors
# (requirements/bench.txt into .venv, requirements/apt-bench.txt with apt: CloudCompare, GNU time),
# builds sfmeval's release binaries, generates bench/data when missing, then runs
# bench/compare.py with the given options and prints one markdown table per operation.
#   scripts/bench.sh                       # full run: 10k/100k/1M points vs the 1M-triangle mesh
#   scripts/bench.sh --quick               # CI size: tiny generated data, one round
#   scripts/bench.sh --markdown bench.md   # also write the tables to a file (see --help)
set -euo pipefail
cd "$(dirname "$0")/.."
missing=()
while read -r p; do
  [[ -n "$p" && "$p" != \#* ]] && ! dpkg -s "$p" >/dev/null 2>&1 && missing+=("$p")
done < requirements/apt-bench.txt
if [ ${#missing[@]} -gt 0 ]; then
  echo "bench: apt-get install ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[ -x .venv/bin/python ] || python3.11 -m venv .venv || python3 -m venv .venv
.venv/bin/pip install -q --disable-pip-version-check -r requirements/bench.txt
quick=0
for a in "$@"; do [ "$a" = --quick ] && quick=1; done
if [ $quick -eq 0 ] && [ ! -f bench/data/mesh_1m.ply ]; then .venv/bin/python bench/generate.py; fi
exec .venv/bin/python bench/compare.py "$@"
