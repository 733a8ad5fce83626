#!/usr/bin/env bash
# `npm start`: installs what is missing (idempotent), builds the wasm and the
# page into dist/, and serves it on 127.0.0.1 (port 8080, or $PORT).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
# The browser is only needed by the tests.
PCPP_SKIP_BROWSER=1 bash scripts/setup.sh
bash scripts/build-web.sh
echo "Offline copy: open dist/pcpp.html directly (file://), no server needed." >&2
exec node scripts/serve.mjs dist
