#!/usr/bin/env python3
"""subscribe_and_shade.py - shade your own points from the streamed LPV.

Subscribes to the volume stream, by default in compression "shq" (SPEC
R5.16: each cell quantised to within --error-bound of its magnitude, deltas
that re-send only the cells that moved beyond it, no message at all for a
tick that moved none; the client ACKs every volume and rebuilds the deltas
against the one it acknowledged), or with --stream exact the exact values
in --format with XOR deltas. After each TICK it computes irradiance at a few
surface points itself from the volume it holds, exactly as
docs/propagation.md section 6 says:

    q = p + 0.5 * cell * n            (half a cell in front of the surface)
    c = trilinear(SH coefficients at q, between cell centres, clamped to the edge)
    E = max(0, c . lobe(-n)) / cell^2  per channel, lobe(m) = (L0, L1 m.y, L1 m.z, L1 m.x)

then asks the server the same points with QUERY_IRRADIANCE and prints both.
Between ticks it moves a small point light ("orbit", 0.5 W/sr) around the
grid so that successive volumes differ (--static to leave the scene alone:
with shq the ticks after the first then send nothing, and the volume held
still answers for them).

    python3 subscribe_and_shade.py --address /tmp/x.sock            # built-in scene, shq
    python3 subscribe_and_shade.py --address /tmp/x.sock --glb box.glb --volumes 5
    python3 subscribe_and_shade.py --address /tmp/x.sock --stream exact --format fp16

The points default to six spots placed relative to the grid (floor, walls,
ceiling, centre); --points FILE reads CSV rows px,py,pz,nx,ny,nz instead.
Exit status 1 when local and server answers disagree beyond --tolerance
(relative to the largest value), 0 otherwise. With shq the local answers
differ from the server's by what the quantisation moved: at most the bound
times the magnitude of the cells looked up, so the default tolerance is
4 x the bound of the largest value.
"""

import argparse
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import lpvd_client  # noqa: E402

# Points as fractions of the grid's extent, with their normals.
DEFAULT_SPOTS = [
    ("floor", (0.5, 0.02, 0.5), (0, 1, 0)),
    ("left wall", (0.02, 0.5, 0.5), (1, 0, 0)),
    ("right wall", (0.98, 0.5, 0.5), (-1, 0, 0)),
    ("ceiling", (0.5, 0.98, 0.5), (0, -1, 0)),
    ("back wall", (0.5, 0.5, 0.02), (0, 0, 1)),
    ("centre, up", (0.5, 0.5, 0.5), (0, 1, 0)),
]


def grid_points(vol):
    pts, nrm, names = [], [], []
    for name, frac, n in DEFAULT_SPOTS:
        pts.append(tuple(vol.origin[a] + frac[a] * vol.dims[a] * vol.cell_size for a in range(3)))
        nrm.append(n)
        names.append(name)
    return pts, nrm, names


def read_points(path):
    pts, nrm, names = [], [], []
    with open(path) as f:
        for i, line in enumerate(f):
            cells = [c.strip() for c in line.replace(";", ",").split(",") if c.strip()]
            if not cells:
                continue
            try:
                v = [float(c) for c in cells]
            except ValueError:
                if i == 0:
                    continue  # header
                raise
            if len(v) != 6:
                raise ValueError("%s:%d: expected px,py,pz,nx,ny,nz" % (path, i + 1))
            pts.append(tuple(v[:3]))
            nrm.append(tuple(v[3:]))
            names.append("row %d" % (i + 1))
    return pts, nrm, names


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--address", default=None, help="daemon address (default: the daemon's default socket)")
    ap.add_argument("--token-file", help="file holding the token")
    ap.add_argument("--glb", help="load this .glb first (else the session's default scene)")
    ap.add_argument("--points", help="CSV of px,py,pz,nx,ny,nz")
    ap.add_argument("--volumes", type=int, default=3, help="ticks to shade after (default 3)")
    ap.add_argument("--stream", default="shq", choices=("shq", "exact"),
                    help="shq: quantised SH to --error-bound (SPEC R5.16, the default); exact: the values in "
                    "--format with XOR deltas")
    ap.add_argument("--error-bound", type=float, default=None,
                    help="shq's bound, a fraction of each cell's magnitude (default: the server's, HELLO's "
                    "volume_codecs)")
    ap.add_argument("--format", default="fp32", choices=("fp32", "fp16"),
                    help="--stream exact's format (fp32 gives bit-identical inputs to the server's lookup)")
    ap.add_argument("--no-tick", action="store_true",
                    help="do not send TICK; wait for the server's periodic ticks (CONFIG tick_rate_hz)")
    ap.add_argument("--static", action="store_true",
                    help="do not move the example's orbiting point light between ticks")
    ap.add_argument("--tolerance", type=float, default=None,
                    help="max |local - server| relative to the largest value (default 4 x the bound for shq, "
                    "1e-3 for fp32, 2e-2 for fp16)")
    args = ap.parse_args(argv)
    shq = args.stream == "shq"

    token = None
    if args.token_file:
        with open(args.token_file) as f:
            token = f.read().strip()
    c = lpvd_client.Client(args.address, token=token, client_name="subscribe_and_shade.py", timeout=300)
    print("connected: %s" % c.hello_reply)
    if args.glb:
        with open(args.glb, "rb") as f:
            print("loaded: %s" % c.scene_load_glb(f.read()))
    # This example shades with the volume's own lookup: R5.14's for the
    # imperfect volume's voxels (which lpvd's default technique, auto, picks on
    # most scenes), R5.7's for the LPV's cells, which is the server's exactly
    # for one volume per cascade: the LPV's normal bins and far field (its
    # defaults) off. A light that moves: the LPV injects it smoothly, so its
    # cells change little by little and the shq deltas are a fraction of
    # the bytes (docs/streaming.md, 1b).
    c.config(normal_bins=False, far_field=False, smooth_injection=not args.static)
    if shq:
        bound = args.error_bound
        if bound is None:
            bound = ((c.volume_codecs or {}).get("error_bound") or {}).get("default", lpvd_client.SHQ_BOUND_DEFAULT)
        tol = args.tolerance if args.tolerance is not None else 4.0 * bound
        c.subscribe("volume", compression="shq", error_bound=bound, delta=True)
    else:
        tol = args.tolerance if args.tolerance is not None else (1e-3 if args.format == "fp32" else 2e-2)
        c.subscribe("volume", format=args.format, delta=True)
    fixed = read_points(args.points) if args.points else None

    worst = 0.0
    vol = None
    for i in range(args.volumes):
        if not args.static and i > 0:
            # A small point light orbiting the grid's centre, so successive
            # volumes differ and the XOR deltas carry real changes.
            b = last_grid
            ang = 2.0 * math.pi * i / max(1, args.volumes)
            pos = (b[0] + (0.5 + 0.25 * math.cos(ang)) * b[3], b[1] + 0.6 * b[4], b[2] + (0.5 + 0.25 * math.sin(ang)) * b[5])
            c.light_set("orbit", "point", 0.5, color=(1.0, 0.9, 0.8), position=pos)
        if args.no_tick:  # the next VOLUME; with shq a periodic tick that moved no cell sends none
            msg = c.next_message()
            if msg is None:
                print("the server said BYE")
                break
            if not isinstance(msg, lpvd_client.Volume):
                continue
            vol, tick = msg, msg.tick
        else:  # with shq, None: no cell moved beyond the bound, the volume held answers for this tick too
            t, msg = c.tick_volume()
            vol, tick = msg if msg is not None else vol, t.get("tick")
        last_grid = vol.origin + tuple(d * vol.cell_size for d in vol.dims)
        pts, nrm, names = fixed if fixed else grid_points(vol)
        local = [vol.irradiance(p, n) for p, n in zip(pts, nrm)]
        server = c.query_irradiance(pts, nrm)
        qtick = c.last_query.get("tick")
        kind = "keyframe" if vol.keyframe else "delta vs tick %s" % vol.base_tick
        if vol.tick != tick:
            kind = "nothing sent for tick %s: no cell moved beyond the bound; held tick %s's" % (tick, vol.tick)
        print("volume tick %s (%s, %s%s, dims %s, cell %.4g m), query answered from tick %s"
              % (tick, kind, vol.format, " shq %g" % vol.error_bound if shq else "", list(vol.dims), vol.cell_size,
                 qtick))
        scale = max([1e-12] + [abs(v) for row in local for v in row] + [abs(float(v)) for row in server for v in row])
        for name, p, n, lo, sv in zip(names, pts, nrm, local, server):
            sv = [float(v) for v in sv]
            d = max(abs(a - b) for a, b in zip(lo, sv)) / scale
            if qtick == tick:
                worst = max(worst, d)
            print("  %-12s p=(%6.3f %6.3f %6.3f) n=(%2g %2g %2g)  local E = %10.5g %10.5g %10.5g  "
                  "server E = %10.5g %10.5g %10.5g W/m^2  (diff %.1e)"
                  % ((name,) + tuple(p) + tuple(n) + tuple(lo) + tuple(sv) + (d,)))
        if qtick != tick:
            print("  (not compared: the server answered from tick %s, this volume is tick %s's)" % (qtick, tick))
    c.unsubscribe("volume")
    c.bye()
    print("largest difference local vs server: %.2e of the largest value (tolerance %.1e)" % (worst, tol))
    return 0 if worst <= tol else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
