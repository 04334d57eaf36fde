#!/usr/bin/env bash
# Idempotent set-up for the web export's viewer and browser tests (docs/web.md), as root on Debian 12:
#  - Debian's chromium (headless WebGL2 on SwiftShader for tests/web);
#  - the npm packages of filter_vertex_brdf/web at the versions package-lock.json pins (npm ci: three.js,
#    esbuild, playwright-core, gltf-validator), when Node.js (>= 20) and npm are present.
# Without npm the build bundles no viewer and the browser tests skip, saying why.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
export DEBIAN_FRONTEND=noninteractive
if ! dpkg-query -W -f='${Status}' chromium 2>/dev/null | grep -q "install ok installed"; then
  echo "setup-web: installing chromium"
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends chromium
fi
WEB="$ROOT/filter_vertex_brdf/web"
if ! command -v npm >/dev/null 2>&1; then
  echo "setup-web: no npm (Node.js 20): the viewer is not bundled and the browser tests skip" >&2
  exit 0
fi
if [ ! -f "$WEB/node_modules/.package-lock.json" ] || ! cmp -s "$WEB/package-lock.json" "$WEB/node_modules/.vbrdf-lock"; then
  echo "setup-web: npm ci in $WEB"
  (cd "$WEB" && npm ci --no-audit --no-fund --loglevel=error)
  cp "$WEB/package-lock.json" "$WEB/node_modules/.vbrdf-lock"
fi
echo "setup-web: ok"
