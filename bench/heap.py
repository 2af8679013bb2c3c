#!/usr/bin/env python3
"""Whether a heap of paper stays a heap: a sheet lying on its floor is gathered by a dozen slow grabs
towards its middle (each takes a point of its rim in turn, carries it in 1 s over an arc to 0.3 of
its way to the middle and lets go, a quarter of a second apart), then left alone for 5 s. Prints its
radius of gyration and the 95th percentile of its hinges' bend (the angle between the normals of
two triangles that share an edge) when the last grab lets go and each second after, and the change
since the release.

    PYTHONPATH=build/release/python /usr/bin/python3 bench/heap.py [PRESET] [key=value ...]

PRESET is crumple unless given; keys set the sheet as in bench/stretch.py. Needs numpy.
"""
import math
import sys
from collections import defaultdict

import numpy as np

import stretch  # bench/stretch.py, beside this script


def gyration(sim):
    p = np.asarray(sim.positions, dtype=np.float64)
    return math.sqrt(((p - p.mean(0)) ** 2).sum(1).mean())


def hinge_pairs(sim):
    """The pairs of triangles that share an edge."""
    shared = defaultdict(list)
    for t, (a, b, c) in enumerate(np.asarray(sim.triangles)):
        for u, v in ((a, b), (b, c), (c, a)):
            shared[(min(u, v), max(u, v))].append(t)
    return np.array([ts for ts in shared.values() if len(ts) == 2])


def bend_p95(sim, pairs):
    x = np.asarray(sim.positions, dtype=np.float64)[np.asarray(sim.triangles)]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    cos = np.clip((n[pairs[:, 0]] * n[pairs[:, 1]]).sum(1), -1.0, 1.0)
    return float(np.percentile(np.degrees(np.arccos(cos)), 95))


def gather(sc, grabs=12):
    """The dozen grabs: rim point k at angle 2 pi k / grabs around the middle, carried over an arc
    (0.06 sheet lengths high) to 0.3 of its way to the middle, 0.07 lengths above the middle's
    height."""
    middle = sc.at((sc.rows // 2) * sc.cols + sc.cols // 2)
    for k in range(grabs):
        t = 2.0 * math.pi * k / grabs
        col = sc.cols // 2 + (sc.cols // 2 - 1) * math.cos(t)
        row = sc.rows // 2 + (sc.rows // 2 - 1) * math.sin(t)
        g = int(round(row)) * sc.cols + int(round(col))
        a = sc.at(g)
        b = [middle[0] + 0.3 * (a[0] - middle[0]), middle[1] + 0.07 * sc.length, middle[2] + 0.3 * (a[2] - middle[2])]
        sc.sim.grab(g)
        sc.carry(stretch.line(a, b, sc.hz, lift=0.06 * sc.length))
        sc.sim.release()
        sc.rest_for(0.25)


def main():
    args = sys.argv[1:]
    preset = args.pop(0) if args and "=" not in args[0] else "crumple"
    sc = stretch.Scene(preset, dict(arg.split("=", 1) for arg in args))
    gather(sc)
    pairs = hinge_pairs(sc.sim)
    r0, b0 = gyration(sc.sim), bend_p95(sc.sim, pairs)
    print(f"{preset}: released: radius of gyration {r0:.3f}, 95th percentile bend {b0:.1f} deg")
    for s in range(1, 6):
        sc.rest_for(1.0)
        r, b = gyration(sc.sim), bend_p95(sc.sim, pairs)
        print(f"{preset}: +{s} s: radius {r:.3f} ({r / r0 - 1:+.1%}), bend {b:.1f} deg ({b / b0 - 1:+.1%})", flush=True)
    print(f"{preset}: most stretch {sc.most:.4f}")


if __name__ == "__main__":
    main()
