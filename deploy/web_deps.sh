#!/usr/bin/env bash
# Installs the dashboard's npm packages (web/package-lock.json) with `npm ci` when web/node_modules
# is missing or older than the lock file; npm's postinstall then copies uPlot into web/vendor/,
# where shore_server serves it (nothing is loaded from the internet at run time).
set -euo pipefail
web=$(cd "$(dirname "${BASH_SOURCE[0]}")/../web" && pwd)
stamp="$web/node_modules/.telltale-lock.sha256"
want=$(sha256sum "$web/package-lock.json" | cut -d' ' -f1)
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ] && [ -f "$web/vendor/uPlot.esm.js" ]; then
  exit 0
fi
command -v npm >/dev/null || { echo "web_deps: npm not found (install Node.js >= 20 and npm)" >&2; exit 1; }
echo "web_deps: npm ci in $web" >&2
(cd "$web" && npm ci --no-audit --no-fund --loglevel=error >&2)
echo "$want" >"$stamp"
