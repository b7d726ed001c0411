#!/usr/bin/env python3
"""wall_chain.py - the LPV's propagation in front of an infinite, uniformly
emitting wall, reduced to one dimension (docs/calibration.md, section 4).

With an infinite wall every cell of a layer holds the same SH coefficients, so
what a cell sends to its four side neighbours comes straight back from them:
each layer is one coefficient vector and only the +z/-z transfers move light
between layers. The step is the full sparse 4x4 transfer of lpv_shared.h (the
lateral band-1 slots stay 0 by symmetry, and the model checks that they do),
with the same flux limiter as techniques/lpv/core/oracle_propagate.c; no occlusion. For the
paper's transport and the central one (docs/propagation.md section 4b) it
prints, in units of the wall's exitance M (the truth is 1 everywhere for a
surface facing the wall, 0 for the wall itself):

- the irradiance a surface facing the wall reads at each cell layer;
- what the wall reads of its own light (self-illumination) with the plain
  lookup, and with normal bins (section 6b: exactly 0);
- the forward momentum a beam keeps per step (band-1 z over band 0, summed).

  python3 bench/accuracy/wall_chain.py
"""
import math

FAR = 0.40066968464623920
SIDE = 0.42343135443673900
L0 = math.sqrt(math.pi) / 2.0   # cosine lobe, band 0
L1 = math.sqrt(math.pi / 3.0)   # cosine lobe, band 1
C0 = 0.5 / math.sqrt(math.pi)
C1 = math.sqrt(3.0 / (4.0 * math.pi))
A = 1.0 / 6.0
B = math.sqrt(3.0) / (4.0 * math.pi) * (FAR + 8.0 * SIDE / math.sqrt(5.0))
TRANSPORTS = {
    "paper": (L1 * C0 * FAR / math.pi, L1 * C1 * FAR / math.pi, 2.0 * L1 * C1 * SIDE / (math.sqrt(5.0) * math.pi)),
    "central": (L1 * C0 * (FAR + 8.0 * SIDE / math.sqrt(5.0)) / math.pi,
                L1 * C1 * (FAR + 16.0 * SIDE / 5.0) / math.pi, L1 * C1 * (2.0 * SIDE / 5.0) / math.pi),
}
LAYERS = 60
SLOT = {"x": 3, "y": 1, "z": 2}


def transfer(c, axis, s, efg):
    """M_d c for direction s * axis (sparse form of lpv_shared.h)."""
    e, f, g = efg
    k = SLOT[axis]
    out = [g * v for v in c]
    out[0] = A * c[0] + s * B * c[k]
    out[k] = s * e * c[0] + f * c[k]
    return out


def step(cells, efg):
    out = [[0.0] * 4 for _ in cells]
    for z, c in enumerate(cells):
        if c[0] <= 0.0:
            continue
        flux = {(a, s): A * c[0] + s * B * c[SLOT[a]] for a in "xyz" for s in (1, -1)}
        sigma = c[0] / sum(max(v, 0.0) for v in flux.values())  # the flux limiter
        for (a, s), fl in flux.items():
            if fl <= 0.0:
                continue
            t = [sigma * v for v in transfer(c, a, s, efg)]
            dz = s if a == "z" else 0      # side neighbours send the same back: stays in the layer
            if 0 <= z + dz < len(cells):
                for i in range(4):
                    out[z + dz][i] += t[i]
    return out


def run(iterations, efg, layers=LAYERS):
    cur = [[0.0] * 4 for _ in range(layers)]
    cur[0] = [L0 / math.pi, 0.0, L1 / math.pi, 0.0]  # exitance 1: a cosine lobe of flux 1, normal +z
    acc = [list(c) for c in cur]
    for _ in range(iterations):
        cur = step(cur, efg)
        for a, c in zip(acc, cur):
            for i in range(4):
                a[i] += c[i]
    for a in acc:  # x and y cancel by symmetry
        assert abs(a[1]) < 1e-9 and abs(a[3]) < 1e-9
    return acc


def momentum(efg, steps=4):
    cur = [[0.0] * 4 for _ in range(2 * steps + 3)]
    cur[1] = [L0, 0.0, L1, 0.0]
    for _ in range(steps):
        cur = step(cur, efg)
    c0 = sum(c[0] for c in cur)
    cz = sum(c[2] for c in cur)
    return cz / c0


def main():
    for name, efg in TRANSPORTS.items():
        print("%s transport (E %.4f, F %.4f, G %.4f); a beam keeps %.3f of band-1 z over band 0 after 4 steps "
              "(a cosine lobe: %.3f)" % (name, efg[0], efg[1], efg[2], momentum(efg), L1 / L0))
        print("  steps | facing the wall at layer 1..8 (truth 1)         | wall reads itself: plain, bins")
        for n in (4, 8, 16, 32, 64):
            acc = run(n, efg)
            facing = [L0 * c[0] + L1 * c[2] for c in acc]          # dot(c, lobe(+z)) / s^2
            plain = max(0.0, L0 * acc[0][0] - L1 * acc[0][2])        # dot(c, lobe(-z))
            print("  %5d | %s | %.2f, 0" % (n, " ".join("%.2f" % v for v in facing[:8]), plain))


if __name__ == "__main__":
    main()
