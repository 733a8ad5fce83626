#!/usr/bin/env bash
# Sets up what is missing, builds the page and serves it on 127.0.0.1.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
PCPP_SKIP_BROWSER=1 bash scripts/setup.sh
echo "The browser page is not built yet; the native CLI is: cargo run --release --bin pcpp -- --help" >&2
