#!/usr/bin/env python3
"""light_lag.py - how many ticks (and how much tick time) the server's light
takes to follow a moved light, per technique (a benchmark, not a test:
nothing is asserted).

    python3 bench/light_lag.py                          # starts its own daemon (build/server/lpvd or --lpvd)
    python3 bench/light_lag.py --unix /tmp/x.sock       # against a running daemon
    python3 bench/light_lag.py --techniques probes --grid 8,16

On the built-in Cornell box, a point light is set at A and the session ticks
until QUERY_IRRADIANCE at 100 points on the floor and walls stops changing
(every point within 0.1 % of the largest answer from one tick to the next,
or --max-ticks): E_A. The light moves to B, 1.5 m away, and settles the
same way: E_B. Then it moves back to A and the session ticks again, one
TICK at a time, until what is left of the change, averaged over the points
(mean |E - E_A| / mean |E_B - E_A|), is at most 50 %, 20 % and 10 %. Each
row gives the ticks and the sum of their tick_ms (the server's own wall time
per tick) to each bound, and what is left when the answers stop changing
again (at the worst point against the largest change, and on average) (two settled answers of a noisy technique differ by their noise, so
a bound below it is never reached: "> N" then means the answers settled
first, at the remainder shown). A technique that recomputes everything each tick (lpv, iv at
its defaults) answers in one tick; one with temporal reuse (the probes'
hysteresis and budget, iv's reprojection) takes more.

Prints a Markdown table. Needs only the Python client (numpy optional).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import lpvd_session  # noqa: E402

A = [-0.6, 1.6, 0.4]
B = [0.6, 1.6, -0.4]


def surface_points():
    """5 x 5 points on the floor, left, right and back walls and ceiling
    of the built-in box ([-1, 1] x [0, 2] x [-1, 1]), facing in."""
    pts, nrm = [], []
    ts = [-0.8, -0.4, 0.0, 0.4, 0.8]
    for u in ts:
        for v in ts:
            pts.append([u, 0.01, v]); nrm.append([0, 1, 0])
            pts.append([-0.99, 1.0 + u, v]); nrm.append([1, 0, 0])
            pts.append([0.99, 1.0 + u, v]); nrm.append([-1, 0, 0])
            pts.append([u, 1.0 + v, -0.99]); nrm.append([0, 0, 1])
    return pts, nrm


def flat(e):
    return [float(x) for row in e for x in row]


def tick_ms(reply):
    return float(reply.get("stats", {}).get("tick_ms", 0.0))


def settle(c, pts, nrm, max_ticks):
    """Ticks until no answer moves by more than 0.1 % of the largest; returns (answers, ticks)."""
    prev = None
    for k in range(1, max_ticks + 1):
        c.tick()
        e = flat(c.query_irradiance(pts, nrm))
        if prev is not None:
            top = max(max(abs(x) for x in e), 1e-30)
            if max(abs(a - b) for a, b in zip(e, prev)) <= 1e-3 * top:
                return e, k
        prev = e
    return prev, max_ticks


def run(addr, technique, grid, max_ticks):
    c = lpvd_session.Client(addr)
    c.hello()
    cfg = {"technique": technique}
    if grid:
        cfg["grid"] = grid
    c.config(**cfg)
    pts, nrm = surface_points()
    light = {"id": "lag", "type": "point", "intensity": 20.0, "position": A}
    c.request(lpvd_session.MSG["LIGHT_SET"], light)
    e_a, _ = settle(c, pts, nrm, max_ticks)
    light["position"] = B
    c.request(lpvd_session.MSG["LIGHT_SET"], light)
    e_b, settled_b = settle(c, pts, nrm, max_ticks)
    change = max(abs(a - b) for a, b in zip(e_a, e_b))
    light["position"] = A
    c.request(lpvd_session.MSG["LIGHT_SET"], light)
    found = {0.5: None, 0.2: None, 0.1: None}
    spent = 0.0
    prev = None
    left = mean_left = float("nan")
    mean_change = sum(abs(a - b) for a, b in zip(e_a, e_b)) / len(e_a)
    for k in range(1, max_ticks + 1):
        spent += tick_ms(c.tick())
        e = flat(c.query_irradiance(pts, nrm))
        left = max(abs(a - b) for a, b in zip(e, e_a)) / max(change, 1e-30)
        mean_left = sum(abs(a - b) for a, b in zip(e, e_a)) / len(e) / max(mean_change, 1e-30)
        for f in found:
            if found[f] is None and mean_left <= f:
                found[f] = (k, spent)
        if all(v is not None for v in found.values()):
            break
        top = max(max(abs(x) for x in e), 1e-30)
        if prev is not None and max(abs(x - y) for x, y in zip(e, prev)) <= 1e-3 * top:
            break  # settled again: what is left stays (noise of the new answer against E_A's)
        prev = e
    c.close()
    return change, mean_change, settled_b, found, left, mean_left


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--unix", help="a running daemon's socket (default: start one)")
    ap.add_argument("--lpvd", default=os.path.join(ROOT, "build", "server", "lpvd"))
    ap.add_argument("--techniques", default="lpv,iv,probes")
    ap.add_argument("--grid", default="8,16", help="grids to try (comma-separated; 0: the preset's)")
    ap.add_argument("--max-ticks", type=int, default=200)
    a = ap.parse_args()
    proc = None
    addr = a.unix
    if not addr:
        addr = os.path.join(tempfile.mkdtemp(prefix="light-lag-"), "lpvd.sock")
        proc = subprocess.Popen([a.lpvd, "serve", "--socket", addr], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        for _ in range(600):
            if os.path.exists(addr):
                break
            time.sleep(0.1)
    try:
        print("| technique | grid | change, max / mean (W/m²) | ticks to settle at B | to 50 % of the change "
              "(ticks / ms) | to 20 % | to 10 % | left when settled, max / mean |")
        print("| --- | ---: | --- | ---: | --- | --- | --- | --- |")
        for t in a.techniques.split(","):
            for g in [int(x) for x in a.grid.split(",")]:
                change, mean_change, settled_b, found, left, mean_left = run(addr, t, g, a.max_ticks)
                cells = []
                for f in (0.5, 0.2, 0.1):
                    v = found[f]
                    cells.append("%d / %.0f" % v if v else "not reached")
                print("| %s | %s | %.3g / %.3g | %d | %s | %s | %s | %.1f %% / %.1f %% |" % (
                    t, g or "preset", change, mean_change, settled_b, cells[0], cells[1], cells[2], 100.0 * left,
                    100.0 * mean_left))
                sys.stdout.flush()
    finally:
        if proc:
            proc.terminate()
            proc.wait()


if __name__ == "__main__":
    main()
