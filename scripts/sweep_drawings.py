#!/usr/bin/env python3
"""Promise 2 measured on many drawings nobody here wrote: `pcpp compare` of
every SVG listed in FILE_LIST on one scan, and `even` against the paper's
planners whose moves keep tol (spec sections 6e and 7).

    python3 scripts/sweep_drawings.py PCPP SCAN PLACE FILE_LIST OUT.json [-- EXTRA FLAGS]

PCPP is the pcpp binary, PLACE a --place value (e.g. centre,0,0.5), FILE_LIST
a file with one SVG path per line (e.g. `npm pack simple-icons`, untarred,
then `find package/icons -name '*.svg' > list`), EXTRA flags go to every run
(e.g. --scan-units cm --up-axis y). Prints each planner's mean defect share,
and the drawings where a paper planner with no move closer than tol has
fewer defects than `even`; writes every drawing's figures to OUT.json. Runs
two at a time.
"""
import concurrent.futures as cf
import json
import os
import subprocess
import sys
import tempfile

PAPER = ("constant", "slope", "pcpp", "pcpp-guarded")


def main():
    args = sys.argv[1:]
    extra = []
    if "--" in args:
        i = args.index("--")
        args, extra = args[:i], args[i + 1:]
    if len(args) != 5:
        sys.exit(__doc__)
    pcpp, scan, place, listing, out = args
    files = [l.strip() for l in open(listing) if l.strip()]
    tmp = tempfile.mkdtemp(prefix="pcpp-sweep-")

    def run(k_f):
        k, f = k_f
        rep = os.path.join(tmp, f"{k}.json")
        r = subprocess.run(
            [pcpp, "compare", "-q", "--scan", scan, "--path", f, "--place", place,
             "--report", rep] + extra,
            capture_output=True, text=True)
        if r.returncode != 0:
            return {"file": f, "error": r.stderr.strip()[:300]}
        with open(rep) as fh:
            d = json.load(fh)
        os.remove(rep)
        res = {"file": f}
        for p in d["planners"]:
            q, m = p["quality"], p["motion"]
            res[p["planner"]] = dict(
                defects=q["contact_pct"] + q["flattening_pct"] + q["floating_pct"],
                mean_abs_error_mm=q["mean_abs_error_mm"], points=q["points"],
                touching_moves=m["touching_moves"], contact_pct=q["contact_pct"],
                backward_moves=m["backward_moves"])
        return res

    with cf.ThreadPoolExecutor(2) as ex:
        results = list(ex.map(run, enumerate(files)))
    os.rmdir(tmp)
    with open(out, "w") as fh:
        json.dump(results, fh)
    ok = [r for r in results if "error" not in r]
    print(f"{len(ok)} drawings planned, {len(results) - len(ok)} refused")
    if not ok:
        return
    for k in PAPER + ("even",):
        safe = sum(r[k]["touching_moves"] == 0 for r in ok)
        mean = sum(r[k]["defects"] for r in ok) / len(ok)
        print(f"{k:13s} mean defects {mean:6.2f}%, moves keep tol on {safe} of {len(ok)}")
    worse = []
    for r in ok:
        safe = {k: r[k]["defects"] for k in PAPER
                if r[k]["touching_moves"] == 0 and r[k]["contact_pct"] == 0}
        if safe and r["even"]["defects"] > min(safe.values()) + 1e-9:
            k = min(safe, key=safe.get)
            worse.append((r["even"]["defects"] - safe[k], r["file"], r["even"]["defects"], k, safe[k]))
    print(f"even has more defects than a paper planner whose moves keep tol on {len(worse)}")
    for _, f, e, k, v in sorted(worse, reverse=True)[:20]:
        print(f"  {os.path.basename(f)}: even {e:.2f}%, {k} {v:.2f}%")


if __name__ == "__main__":
    main()
