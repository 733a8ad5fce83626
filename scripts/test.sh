#!/usr/bin/env bash
# Every test suite, as CI runs it (`npm test`, called by .ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
bash scripts/setup.sh

step() { printf '\n=== %s ===\n' "$*"; }

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (native)"
cargo clippy --all-targets -- -D warnings

step "cargo clippy (wasm32)"
cargo clippy --lib --target wasm32-unknown-unknown -- -D warnings

step "cargo build --lib (wasm32)"
cargo build --lib --target wasm32-unknown-unknown

step "cargo test"
cargo test
