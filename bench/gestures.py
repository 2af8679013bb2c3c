#!/usr/bin/env python3
"""The hand's gestures of bench/stretch.py as input scripts for `tender sim --script`, so that a
program without Python (the GPU proof kit's real-time check) times the gestures bench/realtime.py
times.

    PYTHONPATH=build/release/python python3 bench/gestures.py OUT_DIR [--presets crumple,tender]

writes OUT_DIR/PRESET-GESTURE.txt, each headed by the line that runs it:

    # keys: --preset crumple --set tilt=90 ... --ticks N
    # period_ms: 16.667

The gestures place the hand from the flat sheet's positions alone, so the scripts are written
without running the physics (the Recorder's `run=False`); tests/python/test_module.py checks that a
script replays to the state hash of its gesture run through the module, and that bench/gestures/
holds what this writes.
"""
import os
import struct
import sys

import stretch  # bench/stretch.py, beside this script


def f32(x):
    """x as the float32 the module and the script reader both make of it, written to read back."""
    return "%.9g" % struct.unpack("f", struct.pack("f", x))[0]


class Recorder:
    """A tender.Simulation that writes the hand's events as script lines at the tick they come in
    (the ticks stepped so far), stepping the sheet only when `run`."""

    def __init__(self, sim, run):
        self.sim, self.run, self.tick, self.lines = sim, run, 0, []

    def __getattr__(self, name):
        return getattr(self.sim, name)

    def grab(self, particle):
        self.lines.append(f"{self.tick} grab particle {particle}")
        self.sim.grab(particle)

    def move(self, x, y, z):
        self.lines.append(f"{self.tick} move {f32(x)} {f32(y)} {f32(z)}")
        self.sim.move(x, y, z)

    def squeeze(self, closure):
        self.lines.append(f"{self.tick} squeeze {f32(closure)}")
        self.sim.squeeze(closure)

    def release(self):
        self.lines.append(f"{self.tick} release")
        self.sim.release()

    def step(self, ticks=1):
        if self.run:
            self.sim.step(ticks)
        self.tick += ticks

    def stats(self):
        # (not run: the sheet stands still, and the exact judge of its stats need not look again)
        return self.sim.stats() if self.run else {"max_stretch": 0.0}


def record(preset, gesture, overrides, run):
    """The scene of `gesture` on `preset`, its hand recorded: (scene, header keys, script text)."""
    sc = stretch.Scene(preset, overrides)
    sc.sim = Recorder(sc.sim, run)
    gesture(sc)
    keys = {**stretch.FLOOR_KEYS, **overrides, "top_y": f32(sc.p["top_y"])}
    head = " ".join(["--preset", preset] + [f"--set {k}={v}" for k, v in keys.items()])
    head += f" --ticks {sc.sim.tick}"
    return sc, head, f"# keys: {head}\n# period_ms: {1000.0 / sc.hz:.3f}\n" + "\n".join(sc.sim.lines) + "\n"


def main():
    args = sys.argv[1:]
    if not args or args[0].startswith("-"):
        sys.exit(__doc__)
    out, args = args[0], args[1:]
    presets = ["crumple", "tender"]
    if args[:1] == ["--presets"] and len(args) > 1:
        presets, args = args[1].split(","), args[2:]
    if args:
        sys.exit(__doc__)
    os.makedirs(out, exist_ok=True)
    for preset in presets:
        for name, gesture in stretch.GESTURES:
            text = record(preset, gesture, {}, False)[2]
            path = os.path.join(out, f"{preset}-{name}.txt")
            with open(path + ".tmp", "w") as f:
                f.write(text)
            os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
