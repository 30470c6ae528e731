#!/usr/bin/env bash
# Maintainer's tool, not part of set-up: fetches the report's plotly.js again from the npm
# registry at the version core/web/package-lock.json pins (npm ci, which checks the package's
# integrity hash), and replaces core/web/vendor/plotly-basic.min.js, its licence and
# SHA256SUMS. To move to another release: change the version in core/web/package.json, run
# `npm install --package-lock-only` in core/web, then this script, and commit the four files.
# Needs Node.js and npm (Debian: apt-get install npm) and network access to the registry.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
web="$root/core/web"
pkg="plotly.js-basic-dist-min"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cp "$web/package.json" "$web/package-lock.json" "$work/"
(cd "$work" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error)
mkdir -p "$web/vendor"
cp "$work/node_modules/$pkg/plotly-basic.min.js" "$web/vendor/plotly-basic.min.js"
cp "$work/node_modules/$pkg/LICENSE" "$web/vendor/plotly.js-LICENSE"
(cd "$web/vendor" && sha256sum plotly-basic.min.js plotly.js-LICENSE > SHA256SUMS)
echo "update_plotly: $(head -c 200 "$web/vendor/plotly-basic.min.js" | grep -o 'v[0-9.]*' | head -1) in core/web/vendor"
