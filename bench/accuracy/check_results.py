#!/usr/bin/env python3
"""check_results.py - checks an lpvd-accuracy results.csv (the CI sweep).

  check_results.py RESULTS.csv [--scene NAME --better G:I:R:on|off:MODS:TECHNIQUE --worse G:I:R:on|off:MODS:TECHNIQUE] [--rows N]

Fails (exit 1) unless every expected column is present and filled with a
finite value in every row (except preset: empty for a point that equals no
named preset, else the preset's name), pareto is 0 or 1, at least one row per
scene is on the front, and (with --better/--worse) the "better" point of --scene has a
lower rel_rmse than the "worse" one. No timing is asserted. Standard library only.
"""
import argparse
import csv
import math
import sys

COLUMNS = ["scene", "grid", "iterations", "rsm", "occlusion", "mods", "technique", "ms_per_tick", "ms_rsm",
           "ms_vpl_extract", "ms_inject", "ms_gbuffer", "ms_gv", "ms_propagate", "ms_shade", "rel_rmse", "rel_bias",
           "ref_noise", "rel_rmse_excess", "rel_mae", "pixels", "pareto"]
NUMERIC = COLUMNS[7:]
# preset: the named preset the point equals; legitimately empty for most points.
OPTIONAL = {"preset": ("fast", "balanced", "accurate")}


def key(row):
    return "%s:%s:%s:%s:%s:%s" % (row["grid"], row["iterations"], row["rsm"], row["occlusion"], row["mods"],
                                  row["technique"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--scene")
    ap.add_argument("--better")
    ap.add_argument("--worse")
    ap.add_argument("--rows", type=int)
    a = ap.parse_args()
    problems = []
    with open(a.csv, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS + list(OPTIONAL) if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit("FAIL: %s: missing columns %s" % (a.csv, ", ".join(missing)))
        rows = list(reader)
    if a.rows is not None and len(rows) != a.rows:
        problems.append("%d rows, expected %d" % (len(rows), a.rows))
    if not rows:
        problems.append("no rows")
    for n, row in enumerate(rows, start=2):
        for c in COLUMNS:
            v = (row.get(c) or "").strip()
            if not v:
                problems.append("line %d: column %s is empty" % (n, c))
            elif c in NUMERIC:
                try:
                    x = float(v)
                except ValueError:
                    problems.append("line %d: %s=%r is not a number" % (n, c, v))
                    continue
                if not math.isfinite(x):
                    problems.append("line %d: %s=%s is not finite" % (n, c, v))
        for c, names in OPTIONAL.items():
            v = (row.get(c) or "").strip()
            if v and v not in names:
                problems.append("line %d: %s=%r is not one of %s" % (n, c, v, ", ".join(names)))
        if row.get("pareto") not in ("0", "1"):
            problems.append("line %d: pareto=%r" % (n, row.get("pareto")))
    for scene in sorted({r["scene"] for r in rows}):
        if not any(r["scene"] == scene and r["pareto"] == "1" for r in rows):
            problems.append("scene %s: no point on the Pareto front" % scene)
    if a.better and a.worse:
        sel = {key(r): r for r in rows if r["scene"] == a.scene}
        if a.better not in sel or a.worse not in sel:
            problems.append("scene %s: points %s and %s not both in the CSV" % (a.scene, a.better, a.worse))
        else:
            b, w = float(sel[a.better]["rel_rmse"]), float(sel[a.worse]["rel_rmse"])
            print("%s: %s rel_rmse %.4f, %s rel_rmse %.4f" % (a.scene, a.better, b, a.worse, w))
            if not b < w:
                problems.append("scene %s: %s (rel_rmse %.4f) is not more accurate than %s (%.4f)"
                                % (a.scene, a.better, b, a.worse, w))
    if problems:
        print("FAIL: " + a.csv)
        for p in problems:
            print("  " + p)
        return 1
    print("OK: %s: %d rows, every column filled (preset where the point is one)" % (a.csv, len(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
