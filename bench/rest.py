#!/usr/bin/env python3
"""Whether a crumpled sheet comes to rest, and what the crumple did on the way, on the CPU: the
20 x 30 `crumple` sheet lying flat on its floor (as `Contact.*` in tests/cpu/contact_test.cpp has
it), crumpled by a hand at several paces, then left to lie.

    PYTHONPATH=build/ci/python python3 bench/rest.py [key=value ...]

- fast: the fast crumple (the test's fastCrumpleHand, along its unrounded path): the middle snatched
  up a third of the sheet's length in a twelfth of a second as the hand closes, swung round in
  circles, let go at tick 40, then 8 s on the floor; at each pace in REST_PACES (default
  0.7,0.9,1,1.1,1.3, times the test's);
- calm: the hand's crumple (`Contact.TheHandCrumplesItIntoABall...`): lifted (0.5 s), the hand
  closing (0.5 s), held (0.5 s), lowered (0.5 s), let go, then 4 s on the floor.

For each: the constraints torn, the most intersecting pairs of triangles at any tick (`pairs`), the
most stretch, the fastest particle while the hand moves and after it lets go, and the fastest at the
end (`max_speed`, units/s). How many edges a fast crumple tears changes with the last digit of the
hand's path; a count at one pace says little.
"""
import os
import sys

import tender
from stretch import fast_hand, number  # bench/stretch.py, beside this script


class Scene:
    def __init__(self, overrides):
        keys = {"cols": 20, "rows": 30, "tilt": 90, "pins": "none", "wind": "off", "contact_factor": 0.5}
        keys.update(overrides)
        self.sim = tender.Simulation("crumple", backend="cpu", **keys)
        p = {k: number(v) for k, v in self.sim.params.items()}
        self.sim.set("top_y", p["floor_y"] + 0.5 * p["spacing"])  # flat on the floor
        p = {k: number(v) for k, v in self.sim.params.items()}
        self.cols, self.rows, self.hz = int(p["cols"]), int(p["rows"]), int(p["tick_hz"])
        self.length = (self.rows - 1) * p["spacing"]
        self.middle = (self.rows // 2) * self.cols + self.cols // 2
        self.m = list(self.sim.positions[self.middle][:3])
        self.pairs = 0
        self.stretch = self.moving = self.after = 0.0
        self.sim.grab(self.middle)

    def step(self, held):
        self.sim.step(1)
        s = self.sim.stats()
        self.pairs = max(self.pairs, s["pairs"])
        self.stretch = max(self.stretch, s["max_stretch"])
        if held:
            self.moving = max(self.moving, s["max_speed"])
        else:
            self.after = max(self.after, s["max_speed"])

    def report(self, name):
        s = self.sim.stats()
        print(f"{name}: {s['torn']} torn, {self.pairs} pairs, stretch {self.stretch:.3f}, fastest {self.moving:.1f} "
              f"while held, {self.after:.2f} after, {s['max_speed']:.3f} at the end", flush=True)




def fast(overrides, pace):
    sc = Scene(overrides)
    for t in range(1, 40):
        sc.sim.move(*fast_hand(sc, t, pace))
        if t * pace <= 5:
            sc.sim.squeeze(min(0.2 * t * pace, 1.0))
        sc.step(True)
    sc.sim.release()
    for _ in range(8 * sc.hz):
        sc.step(False)
    sc.report(f"fast x{pace:g}")


def calm(overrides):
    sc = Scene(overrides)
    lift = 0.3 * sc.length
    for t in range(1, 31):
        sc.sim.move(sc.m[0], sc.m[1] + lift * t / 30, sc.m[2])
        sc.step(True)
    for t in range(1, 31):
        sc.sim.squeeze(t / 30)
        sc.step(True)
    for _ in range(30):
        sc.step(True)
    for t in range(1, 31):
        sc.sim.move(sc.m[0], sc.m[1] + lift * (1 - t / 30), sc.m[2])
        sc.step(True)
    sc.sim.release()
    for _ in range(4 * sc.hz):
        sc.step(False)
    sc.report("calm")


def main():
    overrides = dict(arg.split("=", 1) for arg in sys.argv[1:])
    for pace in os.environ.get("REST_PACES", "0.7,0.9,1,1.1,1.3").split(","):
        fast(overrides, float(pace))
    calm(overrides)


if __name__ == "__main__":
    main()
