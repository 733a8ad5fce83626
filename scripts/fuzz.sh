#!/usr/bin/env bash
# A bounded fuzzing run, as CI runs it: every cargo-fuzz target in fuzz/
# for SECONDS_PER_TARGET seconds (default 20), starting from the committed
# seeds (fuzz/seeds/<target>) and the local corpus (fuzz/corpus/<target>,
# git-ignored, grows between runs). Exits non-zero if any target finds a
# crash, a timeout (> 10 s on one input) or an out-of-memory (> 2048 MB);
# the input is saved under fuzz/artifacts/<target>/ (see fuzz/README.md for
# minimising it and turning it into a regression test).
#
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET]
# Needs no stdin and works as root; installs cargo-fuzz (and the nightly
# toolchain libFuzzer needs) only when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

secs="${1:-20}"
if ! [[ "$secs" =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: scripts/fuzz.sh [SECONDS_PER_TARGET] (a whole number > 0, got '$secs')" >&2
  exit 2
fi

if ! cargo +nightly --version >/dev/null 2>&1; then
  rustup toolchain install nightly --profile minimal </dev/null
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz </dev/null
fi

root="$(pwd)"
# One build of every target first, so a compile error is reported as such
# and the per-target timings below are fuzzing only.
cargo +nightly fuzz build </dev/null

mapfile -t targets < <(cargo +nightly fuzz list </dev/null)
failed=()
summary=()
for t in "${targets[@]}"; do
  printf '\n=== fuzz %s (%s s) ===\n' "$t" "$secs"
  mkdir -p "fuzz/corpus/$t"
  log="$(mktemp)"
  # The full log goes to a file; the console gets the progress lines and
  # anything that names a failure.
  set +e
  cargo +nightly fuzz run "$t" "$root/fuzz/corpus/$t" "$root/fuzz/seeds/$t" -- \
    -max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    </dev/null >"$log" 2>&1
  status=$?
  set -e
  grep -E '^(INFO: seed|#[0-9]+[[:space:]]+(INITED|DONE))|panicked|ERROR|SUMMARY|Test unit written|stat::(number_of_executed_units|peak_rss)' "$log" || true
  if [ "$status" -ne 0 ]; then
    tail -n 60 "$log"
  fi
  runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)"
  cov="$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -n 1)"
  rm -f "$log"
  if [ "$status" -ne 0 ]; then
    failed+=("$t")
    summary+=("$t: FAILED (exit $status), inputs in fuzz/artifacts/$t/")
  else
    summary+=("$t: ok, ${runs:-?} runs, ${cov:-cov ?}")
  fi
done

printf '\n=== fuzz summary ===\n'
printf '%s\n' "${summary[@]}"
if [ "${#failed[@]}" -ne 0 ]; then
  echo "fuzzing found problems in: ${failed[*]}" >&2
  exit 1
fi
