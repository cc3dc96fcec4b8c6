#!/usr/bin/env bash
# Builds the page (wasm core, npm package, vendored libraries, demo) and serves it on
# http://127.0.0.1:8000/ (PORT=... to change). Static files only; nothing leaves the machine.
# The server sends the COOP/COEP headers (scripts/serve_site.py), so the page runs threaded.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .tools/bin/wasm-bindgen ] && [ -d www/node_modules ] || scripts/setup-extra.sh
scripts/build-web.sh
port=${PORT:-8000}
echo
echo "sfmeval page: http://127.0.0.1:$port/  (click \"Try the demo\"; Ctrl-C stops)"
exec python3 scripts/serve_site.py "$port" --bind 127.0.0.1 --directory target/web/site
