#!/usr/bin/env python3
"""How far the sheet stretches under the hand: the largest structural length / rest at any tick
(`tender sim`'s `max_stretch`) while a grab drags, folds and crumples a sheet lying on its floor at a
hand's pace, crumples it faster, tosses it and yanks it, on the CPU.

    PYTHONPATH=build/ci/python python3 bench/stretch.py crumple [key=value ...]

- drag: a corner of the far row carried 1.5 sheet lengths back over the sheet, and up, in 1.5 s;
- fold: the middle of the far row carried over an arc to just above the near row (1.5 s), held
  there (1 s), carried back (1.5 s) to 1.5 spacings above where it started, and let go (0.5 s);
- crumple: the middle grabbed and lifted (1 s), the hand closed (1 s), held (1 s), and the ball
  lowered until it rests on the floor (1 s);
- fast: bench/rest.py's fast crumple (the middle snatched up as the hand closes, swung round, let go
  at tick 40), then a second on the floor;
- toss: a corner swung up and forwards in 12 ticks and let go, then a second of flight and landing;
- yank: the middle of the far row pulled away at four sheet lengths a second for half a second, let
  go, then half a second more.
"""
import math
import sys

import tender


def number(text):
    try:
        return float(text)
    except ValueError:
        return text


# What every scene sets over its preset: the sheet lying on its floor, nothing holding it, no wind
FLOOR_KEYS = {"tilt": 90, "pins": "none", "wind": "off"}


class Scene:
    def __init__(self, preset, overrides):
        keys = {**FLOOR_KEYS, **overrides}
        self.sim = tender.Simulation(preset, **keys)
        p = {k: number(v) for k, v in self.sim.params.items()}
        self.sim.set("top_y", p["floor_y"] + 0.5 * p["spacing"])  # flat on the floor
        self.p = {k: number(v) for k, v in self.sim.params.items()}
        self.cols, self.rows = int(self.p["cols"]), int(self.p["rows"])
        self.s, self.hz = self.p["spacing"], int(self.p["tick_hz"])
        self.length = (self.rows - 1) * self.s
        self.most = 0.0

    def step(self):
        self.sim.step(1)
        self.most = max(self.most, self.sim.stats()["max_stretch"])

    def rest_for(self, seconds):
        for _ in range(int(seconds * self.hz)):
            self.step()

    def carry(self, points):
        for q in points:
            self.sim.move(*q)
            self.step()

    def at(self, particle):
        return list(self.sim.positions[particle][:3])


def line(a, b, n, lift=0.0):
    return [[a[k] + (b[k] - a[k]) * t / n + (lift * math.sin(math.pi * t / n) if k == 1 else 0.0) for k in range(3)]
            for t in range(1, n + 1)]


def drag(sc):
    g = (sc.rows - 1) * sc.cols
    a = sc.at(g)
    b = [a[0] + 0.3 * sc.length, a[1] + 0.3 * sc.length, a[2] + 1.5 * sc.length]
    sc.sim.grab(g)
    sc.carry(line(a, b, int(1.5 * sc.hz)))


def fold(sc):
    g = (sc.rows - 1) * sc.cols + sc.cols // 2
    a = sc.at(g)
    over = [a[0], a[1] + 1.5 * sc.s, a[2] + sc.length - 0.5 * sc.s]
    back = [a[0], a[1] + 1.5 * sc.s, a[2]]
    n = int(1.5 * sc.hz)
    sc.sim.grab(g)
    sc.carry(line(a, over, n, 0.4 * sc.length))
    sc.rest_for(1.0)
    sc.carry(line(over, back, n, 0.4 * sc.length))
    sc.sim.release()
    sc.rest_for(0.5)


def crumple(sc):
    p = sc.p
    # The fist's radius (SimParams::handBallRadius): the sheet's area in layers a collision radius
    # thick at a packing of a quarter, within the hand's reach
    area = (sc.cols - 1) * (sc.rows - 1) * sc.s * sc.s
    ball = min((area * p["collision_factor"] * sc.s / 0.25 * 3 / (4 * math.pi)) ** (1 / 3), p["hand_reach"])
    g = (sc.rows // 2) * sc.cols + sc.cols // 2
    m = sc.at(g)
    top = [m[0], m[1] + 0.3 * sc.length, m[2]]
    rest = [m[0], max(m[1], p["floor_y"] + ball + sc.s), m[2]]
    sc.sim.grab(g)
    sc.carry(line(m, top, sc.hz))
    for t in range(1, sc.hz + 1):
        sc.sim.squeeze(t / sc.hz)
        sc.step()
    sc.rest_for(1.0)
    sc.carry(line(top, rest, sc.hz))


def fast_hand(sc, t, pace):
    """Where the fast crumple's hand is at tick t, at `pace` times its speed (sc.m: the middle)."""
    at = t * pace
    if at <= 5:
        return [sc.m[0], sc.m[1] + sc.length * 0.07 * at, sc.m[2]]
    a = 0.35 * (at - 6)
    return [sc.m[0] + 0.14 * sc.length * math.cos(a), sc.m[1] + sc.length * (0.35 - 0.09 * math.sin(a)),
            sc.m[2] + 0.14 * sc.length * math.sin(a)]


def fast(sc):
    g = (sc.rows // 2) * sc.cols + sc.cols // 2
    sc.middle, sc.m = g, sc.at(g)
    sc.sim.grab(g)
    for t in range(1, 40):
        sc.sim.move(*fast_hand(sc, t, 1.0))
        if t <= 5:
            sc.sim.squeeze(min(0.2 * t, 1.0))
        sc.step()
    sc.sim.release()
    sc.rest_for(1.0)


def toss(sc):
    a = sc.at(0)
    sc.sim.grab(0)
    for k in range(1, 13):
        sc.sim.move(a[0] + 0.02 * k * sc.length, a[1] + 0.05 * k * sc.length, a[2] + 0.08 * k * sc.length)
        sc.step()
    sc.sim.release()
    sc.rest_for(1.0)


def yank(sc):
    g = (sc.rows - 1) * sc.cols + sc.cols // 2
    a = sc.at(g)
    n = sc.hz // 2
    sc.sim.grab(g)
    sc.carry(line(a, [a[0], a[1] + 0.5 * sc.length, a[2] - 2.0 * sc.length], n))
    sc.sim.release()
    sc.rest_for(0.5)


GESTURES = (("drag", drag), ("fold", fold), ("crumple", crumple), ("fast", fast), ("toss", toss), ("yank", yank))


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    overrides = dict(arg.split("=", 1) for arg in sys.argv[2:])
    for name, gesture in GESTURES:
        sc = Scene(sys.argv[1], overrides)
        gesture(sc)
        print(f"{sys.argv[1]} {name}: most stretch {sc.most:.4f}", flush=True)


if __name__ == "__main__":
    main()
