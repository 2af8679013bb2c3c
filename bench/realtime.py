#!/usr/bin/env python3
"""Whether the paper keeps to real time: each gesture of the hand on a sheet lying on its floor, for
each preset, with the median and the slowest tick against the tick's period (1 / tick_hz).

    PYTHONPATH=build/release/python python3 bench/realtime.py [--presets crumple,tender] [key=value ...]

The gestures (each tick timed around `Simulation.step(1)` alone):
- drag, fold and crumple: bench/stretch.py's (a corner dragged back over the sheet; the far edge
  folded over and back and let go; the middle lifted, the hand closed, held, lowered);
- fast: bench/rest.py's fast crumple (the middle snatched up as the hand closes, swung round, let go
  at tick 40), then a second on the floor;
- toss: a corner swung up and forwards in 12 ticks and let go, then a second of flight and landing;
- yank: the middle of the far row pulled away at four sheet lengths a second for half a second, let
  go, then half a second more.

Keys after the options set every sheet (`backend=gpu`, `threads=1`, `contact_factor=0`, ...). The
table is Markdown; a row is within real time when its slowest tick fits the period.
"""
import statistics
import sys
import time

import rest  # bench/rest.py, beside this script
import stretch  # bench/stretch.py, beside this script
from stretch import line


class Timed(stretch.Scene):
    """stretch.Scene whose ticks are timed (and its stats not read)."""

    def __init__(self, preset, overrides):
        super().__init__(preset, overrides)
        self.ms = []

    def step(self):
        start = time.perf_counter()
        self.sim.step(1)
        self.ms.append(1000.0 * (time.perf_counter() - start))

    def rest_for(self, seconds):
        for _ in range(int(seconds * self.hz)):
            self.step()


def fast(sc):
    g = (sc.rows // 2) * sc.cols + sc.cols // 2
    sc.middle, sc.m = g, sc.at(g)
    sc.sim.grab(g)
    for t in range(1, 40):
        sc.sim.move(*rest.fast_hand(sc, t, 1.0))
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


GESTURES = (("drag", stretch.drag), ("fold", stretch.fold), ("crumple", stretch.crumple), ("fast", fast), ("toss", toss),
            ("yank", yank))


def main():
    args = sys.argv[1:]
    presets = ["crumple", "tender"]
    if args[:1] == ["--presets"] and len(args) > 1:
        presets, args = args[1].split(","), args[2:]
    if any(not a.count("=") for a in args):
        sys.exit(__doc__)
    overrides = dict(arg.split("=", 1) for arg in args)
    print("| preset | gesture | ticks | median ms | slowest ms | period ms | median / period | slowest / period |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for preset in presets:
        for name, gesture in GESTURES:
            sc = Timed(preset, overrides)
            gesture(sc)
            period = 1000.0 / sc.hz
            median, slowest = statistics.median(sc.ms), max(sc.ms)
            print(f"| {preset} | {name} | {len(sc.ms)} | {median:.1f} | {slowest:.1f} | {period:.1f} | "
                  f"{median / period:.2f} | {slowest / period:.2f} |", flush=True)


if __name__ == "__main__":
    main()
