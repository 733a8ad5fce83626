#!/usr/bin/env python3
"""Times whole commands for `npm run bench` (issue 15): wall time and peak
resident set of each run, measured by the kernel (os.wait4's rusage), the
median and the best of --runs, as one JSON line on stdout.

    bench_e2e.py --runs 5 -- pcpp plan ...
"""
import json
import os
import statistics
import subprocess
import sys
import time


def run_once(cmd):
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        sys.exit(f"[bench] {' '.join(cmd)} exited with {code}")
    # ru_maxrss is in KiB on Linux.
    return wall, usage.ru_maxrss * 1024, usage.ru_utime + usage.ru_stime


def main():
    args = sys.argv[1:]
    runs = 5
    if args[:1] == ["--runs"]:
        runs = int(args[1])
        args = args[2:]
    if args[:1] != ["--"] or len(args) < 2:
        sys.exit("usage: bench_e2e.py [--runs N] -- COMMAND...")
    cmd = args[1:]
    results = [run_once(cmd) for _ in range(runs)]
    walls = [r[0] for r in results]
    print(json.dumps({
        "runs": runs,
        "wall_median_s": statistics.median(walls),
        "wall_best_s": min(walls),
        "cpu_median_s": statistics.median(r[2] for r in results),
        "peak_bytes": max(r[1] for r in results),
    }))


if __name__ == "__main__":
    main()
