#!/usr/bin/env bash
# Builds the browser page into dist/: the wasm package (wasm-pack, release),
# the page with its modules (dist/index.html, dist/web/, dist/pkg/), and one
# self-contained file for offline use (dist/pcpp.html, scripts/single-file.mjs).
#
# wasm-opt is off (Cargo.toml's [package.metadata.wasm-pack] sections):
# wasm-pack's own binaryen download fails here and Debian's binaryen 108
# produces a module that does not instantiate (shared/toolchain.md). Put
# binaryen@132 from npm on PATH and set PCPP_WASM_OPT=1 to shrink the .wasm.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

wasm-pack build --target web --release --out-dir pkg --no-pack --no-typescript
if [ "${PCPP_WASM_OPT:-0}" = 1 ] && command -v wasm-opt >/dev/null 2>&1; then
  wasm-opt -O2 --enable-bulk-memory --enable-nontrapping-float-to-int --enable-sign-ext \
    --enable-mutable-globals pkg/pcpp_bg.wasm -o pkg/pcpp_bg.wasm
fi

rm -rf dist
mkdir -p dist/web dist/pkg
cp index.html dist/
cp web/*.js web/*.css dist/web/
cp pkg/pcpp.js pkg/pcpp_bg.wasm dist/pkg/
node scripts/single-file.mjs dist/index.html dist/pcpp.html
echo "built dist/ ($(du -sh dist | cut -f1)); single file: dist/pcpp.html" >&2
