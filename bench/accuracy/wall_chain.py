#!/usr/bin/env python3
"""wall_chain.py - the LPV's propagation in front of an infinite, uniformly
emitting wall, reduced to one dimension (docs/calibration.md, section 4).

With an infinite wall every cell of a layer holds the same SH coefficients, so
what a cell sends to its four side neighbours comes straight back from them:
each layer is one (c0, cz) pair and only the +z/-z transfers move light
between layers. Same constants and flux limiter as shaders/lpv_shared.h and
core/oracle_propagate.c; no occlusion. Prints the irradiance a surface facing
the wall reads at the centre of each cell layer, in units of the wall's
exitance M (the truth is 1 everywhere), for several iteration counts.

  python3 bench/accuracy/wall_chain.py
"""
import math

A = 1.0 / 6.0
B = 0.26402916857
E = 0.03681679578
F = 0.06376856086
G = 0.06027651556
L0 = math.sqrt(math.pi) / 2.0   # cosine lobe, band 0
L1 = math.sqrt(math.pi / 3.0)   # cosine lobe, band 1
LAYERS = 40


def step(cells):
    out = [[0.0, 0.0] for _ in cells]
    for z, (c0, cz) in enumerate(cells):
        if c0 <= 0.0:
            continue
        up, down, side = A * c0 + B * cz, A * c0 - B * cz, A * c0
        sigma = c0 / (max(up, 0.0) + max(down, 0.0) + 4.0 * side)  # the flux limiter
        out[z][0] += sigma * 4.0 * side           # the side neighbours' exchange
        out[z][1] += sigma * 4.0 * G * cz
        if up > 0.0 and z + 1 < len(cells):
            out[z + 1][0] += sigma * up
            out[z + 1][1] += sigma * (E * c0 + F * cz)
        if down > 0.0 and z > 0:
            out[z - 1][0] += sigma * down
            out[z - 1][1] += sigma * (-E * c0 + F * cz)
    return out


def profile(iterations, layers=LAYERS):
    # cell size 1, exitance 1: the first layer holds a cosine lobe of flux 1
    cur = [[0.0, 0.0] for _ in range(layers)]
    cur[0] = [L0 / math.pi, L1 / math.pi]
    acc = [list(c) for c in cur]
    for _ in range(iterations):
        cur = step(cur)
        for a, c in zip(acc, cur):
            a[0] += c[0]
            a[1] += c[1]
    # a surface facing the wall (n = -z) reads dot(c, lobe(+z)) / s^2
    return [L0 * c0 + L1 * cz for c0, cz in acc]


def main():
    print("E / M at the centre of cell layer 1..8 in front of an infinite wall (truth: 1)")
    for n in (0, 4, 8, 16, 32, 64):
        print("%3d steps: %s" % (n, " ".join("%.2f" % v for v in profile(n)[:8])))


if __name__ == "__main__":
    main()
