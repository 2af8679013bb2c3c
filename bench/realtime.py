#!/usr/bin/env python3
"""Whether the paper keeps to real time: each gesture of the hand on a sheet lying on its floor, for
each preset, with the median and the slowest tick against the tick's period (1 / tick_hz).

    PYTHONPATH=build/release/python python3 bench/realtime.py [--presets crumple,tender] [key=value ...]

The gestures are bench/stretch.py's (its docstring has them): a drag, a fold and unfold, the hand's
crumple, the fast crumple, a toss and a yank; each tick is timed around `Simulation.step(1)` alone.

Keys after the options set every sheet (`backend=gpu`, `threads=1`, `contact_factor=0`, ...). The
table is Markdown; a row is within real time when its slowest tick fits the period.
"""
import statistics
import sys
import time

import stretch  # bench/stretch.py, beside this script


class Timed(stretch.Scene):
    """stretch.Scene whose ticks are timed (and its stats not read)."""

    def __init__(self, preset, overrides):
        super().__init__(preset, overrides)
        self.ms = []

    def step(self):
        start = time.perf_counter()
        self.sim.step(1)
        self.ms.append(1000.0 * (time.perf_counter() - start))


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
        for name, gesture in stretch.GESTURES:
            sc = Timed(preset, overrides)
            gesture(sc)
            period = 1000.0 / sc.hz
            median, slowest = statistics.median(sc.ms), max(sc.ms)
            print(f"| {preset} | {name} | {len(sc.ms)} | {median:.1f} | {slowest:.1f} | {period:.1f} | "
                  f"{median / period:.2f} | {slowest / period:.2f} |", flush=True)


if __name__ == "__main__":
    main()
