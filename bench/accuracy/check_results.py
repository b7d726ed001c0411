#!/usr/bin/env python3
"""check_results.py - checks an lpvd-accuracy results.csv (the CI sweep).

  check_results.py RESULTS.csv [--scene NAME --better POINT --worse POINT [--metric COLUMN]] [--rows N]
                   [--lookup-steps LIST] [--not-worse KNOB=POINT>POINT[>POINT...]]...

POINT is G:I:R:on|off:MODS:TECHNIQUE for an LPV point, or
iv:RES:POINTS:RAYS:BOUNCES:on|off:NEIGHBOURS for an imperfect-volume one.

Fails (exit 1) unless every expected column is present and filled with a
finite value in every row (except preset: empty for a point that equals no
named preset, else the preset's name; and for technique iv the LPV's own knobs
grid, iterations, occlusion and mods, which are empty, while its iv_* columns,
empty on LPV rows, are filled and its ref_bounces equals its iv_bounces, or
is 0 with 3 or more: converged light, its tail adding the bounces after them),
pareto is 0 or 1, at least one row per scene is on the front, and (with
--better/--worse) the "better" point of --scene has a lower --metric (default
rel_rmse, the error against converged light; rel_rmse_own: against the
reference with the point's own bounce count) than the "worse" one, and (with
--lookup-steps 1,2) every point ran at each listed lookup step (the
lookup_step column). Since issue 30 rel_rmse, rel_bias and rel_mae are against
converged light and rel_*_own against the own-bounce reference: every row must
have them all, ref_noise2 > 0, at_ref_noise 0 or 1 and equal to
rel_rmse < 2 ref_noise2, and rel_bias < rel_bias_own (converged light holds
more light than any fewer bounces, so a frame is darker against it: a row
where it is not was scored against the wrong reference). No timing is
asserted. With --not-worse (issue 30, "knobs that never make it worse"; any
number of them), KNOB=P1>P2>... lists one knob's settings from lower to
higher quality: in every scene of the CSV, every higher setting Pj must score
rel_rmse(Pj) <= rel_rmse(Pi) + 2 ref_noise2 against every lower one Pi (i < j),
i.e. not worse against converged light by more than twice the converged
reference's noise measured from its two seeds. Standard library only.
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
# Issue 30: the score against the own-bounce reference beside the converged one.
OWN_COLUMNS = ["rel_rmse_own", "rel_bias_own", "rel_mae_own", "ref_noise_own", "ref_noise2", "at_ref_noise"]
LPV_ONLY = {"grid", "iterations", "occlusion", "mods"}  # empty on iv rows
# preset: the named preset the point equals; legitimately empty for most points.
OPTIONAL = {"preset": ("fast", "balanced", "accurate")}


def key(row):
    if row["technique"] == "iv":
        return "iv:" + ":".join(row[c] for c in IV_KNOBS)
    return "%s:%s:%s:%s:%s:%s" % (row["grid"], row["iterations"], row["rsm"], row["occlusion"], row["mods"],
                                  row["technique"])


def not_worse(rows, chain):
    """--not-worse KNOB=P1>P2>...: per scene, a higher setting may not score a
    rel_rmse above a lower one's plus 2 ref_noise2. Prints every pair with its
    margin (tolerance minus excess; negative fails) and returns the problems."""
    knob, _, points = chain.partition("=")
    points = points.split(">")
    if not knob or len(points) < 2:
        return ["--not-worse %r: want KNOB=P1>P2[>...]" % chain]
    problems = []
    for scene in sorted({r["scene"] for r in rows}):
        sel = {key(r): r for r in rows if r["scene"] == scene}
        missing = [p for p in points if p not in sel]
        if missing:
            problems.append("scene %s, knob %s: points %s not in the CSV" % (scene, knob, ", ".join(missing)))
            continue
        for i in range(len(points)):
            for j in range(i + 1, len(points)):
                lo, hi = sel[points[i]], sel[points[j]]
                e_lo, e_hi = float(lo["rel_rmse"]), float(hi["rel_rmse"])
                tol = 2.0 * float(hi["ref_noise2"])
                ok = e_hi <= e_lo + tol
                print("%-4s %-9s %-10s %s %.4f -> %s %.4f (%+.4f, allowed +%.4f)"
                      % ("ok" if ok else "FAIL", scene, knob, points[i], e_lo, points[j], e_hi, e_hi - e_lo, tol))
                if not ok:
                    problems.append("scene %s, knob %s: %s scores rel_rmse %.4f, worse than the lower %s's %.4f by "
                                    "%.4f > 2 ref_noise2 = %.4f" % (scene, knob, points[j], e_hi, points[i], e_lo,
                                                                    e_hi - e_lo, tol))
    return problems


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--scene")
    ap.add_argument("--better")
    ap.add_argument("--worse")
    ap.add_argument("--rows", type=int)
    ap.add_argument("--lookup-steps")
    ap.add_argument("--metric", default="rel_rmse", choices=("rel_rmse", "rel_rmse_own"))
    ap.add_argument("--not-worse", action="append", default=[], metavar="KNOB=P1>P2[>P3...]")
    a = ap.parse_args()
    problems = []
    with open(a.csv, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS + list(OPTIONAL) + IV_COLUMNS + OWN_COLUMNS
                   if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit("FAIL: %s: missing columns %s" % (a.csv, ", ".join(missing)))
        rows = list(reader)
    if a.rows is not None and len(rows) != a.rows:
        problems.append("%d rows, expected %d" % (len(rows), a.rows))
    if not rows:
        problems.append("no rows")
    for n, row in enumerate(rows, start=2):
        iv = row.get("technique") == "iv"
        for c in COLUMNS + OWN_COLUMNS + (IV_COLUMNS if iv else []):
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
            elif c in NUMERIC or c in OWN_COLUMNS:
                try:
                    x = float(v)
                except ValueError:
                    problems.append("line %d: %s=%r is not a number" % (n, c, v))
                    continue
                if not math.isfinite(x):
                    problems.append("line %d: %s=%s is not finite" % (n, c, v))
        try:
            rmse, noise2 = float(row["rel_rmse"]), float(row["ref_noise2"])
            bias, bias_own = float(row["rel_bias"]), float(row["rel_bias_own"])
            if not noise2 > 0:
                problems.append("line %d: ref_noise2=%s (the converged reference's noise from two seeds)"
                                % (n, row["ref_noise2"]))
            if row["at_ref_noise"] != ("1" if rmse < 2 * noise2 else "0"):
                problems.append("line %d: at_ref_noise=%s with rel_rmse %s and ref_noise2 %s"
                                % (n, row["at_ref_noise"], row["rel_rmse"], row["ref_noise2"]))
            # ref_bounces 0: the point's own reference is converged light itself (an imperfect volume's tail),
            # so its own figures are its converged ones and there is nothing to compare
            all_bounces = (row.get("ref_bounces") or "").strip() == "0"
            if not all_bounces and not bias < bias_own:
                problems.append("line %d: rel_bias %+.4f vs converged light is not below rel_bias_own %+.4f vs %s "
                                "bounce(s)" % (n, bias, bias_own, row.get("ref_bounces")))
        except (KeyError, ValueError):
            pass  # reported above as empty or not a number
        refb, ivb = (row.get("ref_bounces") or "").strip(), (row.get("iv_bounces") or "").strip()
        if iv and refb != ivb and not (refb == "0" and ivb.isdigit() and int(ivb) >= 3):
            problems.append("line %d: iv point with iv_bounces=%s compared with a %s-bounce reference"
                            % (n, ivb, refb))
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
            m = a.metric
            b, w = float(sel[a.better][m]), float(sel[a.worse][m])
            print("%s: %s %s %.4f, %s %s %.4f" % (a.scene, a.better, m, b, a.worse, m, w))
            if not b < w:
                problems.append("scene %s: %s (%s %.4f) is not more accurate than %s (%.4f)"
                                % (a.scene, a.better, m, b, a.worse, w))
    for chain in a.not_worse:
        problems += not_worse(rows, chain)
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
