#!/usr/bin/env python3
"""check_results.py - checks an lpvd-accuracy results.csv (the CI sweep).

  check_results.py RESULTS.csv [--scene NAME --better POINT --worse POINT] [--rows N]
                   [--lookup-steps LIST]

POINT is G:I:R:on|off:MODS:TECHNIQUE for an LPV point, or
iv:RES:POINTS:RAYS:BOUNCES:on|off:NEIGHBOURS for an imperfect-volume one.

Fails (exit 1) unless every expected column is present and filled with a
finite value in every row (except preset: empty for a point that equals no
named preset, else the preset's name; and for technique iv the LPV's own knobs
grid, iterations, occlusion and mods, which are empty, while its iv_* columns,
empty on LPV rows, are filled and its ref_bounces equals its iv_bounces),
pareto is 0 or 1, at least one row per scene is on the front, and (with
--better/--worse) the "better" point of --scene has a lower rel_rmse than the
"worse" one, and (with --lookup-steps 1,2) every point ran at each listed
lookup step (the lookup_step column). No timing is asserted. Standard
library only.
"""
import argparse
import csv
import math
import sys

COLUMNS = ["scene", "grid", "iterations", "rsm", "occlusion", "mods", "technique", "ms_per_tick", "ms_rsm",
           "ms_vpl_extract", "ms_inject", "ms_gbuffer", "ms_gv", "ms_propagate", "ms_shade", "rel_rmse", "rel_bias",
           "ref_noise", "rel_rmse_excess", "rel_mae", "pixels", "pareto"]
NUMERIC = COLUMNS[7:]
# The imperfect volume's (technique iv) knobs and stages, after the LPV's columns.
IV_KNOBS = ["iv_resolution", "iv_points", "iv_rays", "iv_bounces", "iv_reprojection", "iv_neighbours"]
IV_COLUMNS = IV_KNOBS + ["ms_iv_points", "ms_iv_reproject", "ms_iv_resolve", "ms_iv_gather", "ms_iv_ao",
                         "ref_bounces", "rel_rmse_1b"]
LPV_ONLY = {"grid", "iterations", "occlusion", "mods"}  # empty on iv rows
# preset: the named preset the point equals; legitimately empty for most points.
OPTIONAL = {"preset": ("fast", "balanced", "accurate")}


def key(row):
    if row["technique"] == "iv":
        return "iv:" + ":".join(row[c] for c in IV_KNOBS)
    return "%s:%s:%s:%s:%s:%s" % (row["grid"], row["iterations"], row["rsm"], row["occlusion"], row["mods"],
                                  row["technique"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--scene")
    ap.add_argument("--better")
    ap.add_argument("--worse")
    ap.add_argument("--rows", type=int)
    ap.add_argument("--lookup-steps")
    a = ap.parse_args()
    problems = []
    with open(a.csv, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS + list(OPTIONAL) + IV_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit("FAIL: %s: missing columns %s" % (a.csv, ", ".join(missing)))
        rows = list(reader)
    if a.rows is not None and len(rows) != a.rows:
        problems.append("%d rows, expected %d" % (len(rows), a.rows))
    if not rows:
        problems.append("no rows")
    for n, row in enumerate(rows, start=2):
        iv = row.get("technique") == "iv"
        for c in COLUMNS + (IV_COLUMNS if iv else []):
            v = (row.get(c) or "").strip()
            if iv and c in LPV_ONLY:
                if v:
                    problems.append("line %d: iv row has %s=%r (the LPV's knob; empty expected)" % (n, c, v))
                continue
            if c == "iv_reprojection":
                if v not in ("on", "off"):
                    problems.append("line %d: iv_reprojection=%r" % (n, v))
                continue
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
        if iv and (row.get("ref_bounces") or "").strip() != (row.get("iv_bounces") or "").strip():
            problems.append("line %d: iv point with iv_bounces=%s compared with a %s-bounce reference"
                            % (n, row.get("iv_bounces"), row.get("ref_bounces")))
        if not iv and any((row.get(c) or "").strip() for c in IV_KNOBS):
            problems.append("line %d: %s row has iv_* knobs filled" % (n, row.get("technique")))
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
    if a.lookup_steps:
        want = sorted(a.lookup_steps.split(","))
        by_point = {}
        for r in rows:
            by_point.setdefault((r["scene"], key(r)), []).append((r.get("lookup_step") or "").strip())
        for (scene, k), got in sorted(by_point.items()):
            if sorted(got) != want:
                problems.append("scene %s point %s: lookup steps %s, expected %s" % (scene, k, got, want))
    if problems:
        print("FAIL: " + a.csv)
        for p in problems:
            print("  " + p)
        return 1
    print("OK: %s: %d rows, every column filled (preset where the point is one)" % (a.csv, len(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
