#!/usr/bin/env bash
# Every test suite, as CI runs it (`npm test`, called by .ci/run). Exits
# non-zero on the first failure; needs no stdin and works as root.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
bash scripts/setup.sh
# setup.sh installs npm dependencies only when they are missing; CI starts
# from a fresh clone, and `npm ci` keeps them exactly as package-lock.json.
if [ ! -d node_modules/playwright-core ]; then
  npm ci --no-audit --no-fund </dev/null
fi

step() { printf '\n=== %s ===\n' "$*"; }

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (native)"
cargo clippy --all-targets -- -D warnings

step "cargo clippy (wasm32)"
cargo clippy --lib --target wasm32-unknown-unknown -- -D warnings
cargo clippy --target wasm32-unknown-unknown --test wasm_core -- -D warnings

step "cargo build --lib (wasm32)"
cargo build --lib --target wasm32-unknown-unknown

step "cargo test"
cargo test

step "wasm tests in Node (wasm-pack test --node, tests/wasm_core.rs)"
wasm-pack test --node -- --test wasm_core

step "web build (scripts/build-web.sh)"
bash scripts/build-web.sh

step "browser tests (node --test tests/browser/, headless Chromium)"
# The browser tests compare the page's G-code with the CLI's.
cargo build --bin pcpp
node --test tests/browser/

step "fuzzing, bounded (scripts/fuzz.sh, 10 s per target)"
# The long runs and their figures are in fuzz/README.md.
bash scripts/fuzz.sh "${PCPP_FUZZ_SECONDS:-10}"
