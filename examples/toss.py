#!/usr/bin/env python3
"""Tosses a receipt: the crumple preset, grab a corner, drag it, let go with the drag velocity, let it
fly and land for two seconds, and save the sheet as binary glTF.

    PYTHONPATH=build/ci/python python3 examples/toss.py [toss.glb]
"""
import sys

import tender

out = sys.argv[1] if len(sys.argv) > 1 else "toss.glb"
# release=drag in crumple: a release keeps the drag velocity. No pins: the hand holds the sheet.
sim = tender.Simulation(preset="crumple", backend="cpu", pins="none")
hz = float(sim.params["tick_hz"])

corner = 0  # the top left corner
sim.grab(corner)
sim.step(int(hz // 2))  # hanging from the corner for half a second
x, y, z = (float(v) for v in sim.positions[corner])
for k in range(1, 13):  # a swing up and forwards, a little further each tick
    sim.move(x + 0.05 * k, y + 0.12 * k, z + 0.2 * k)
    sim.step(1)
sim.release()
sim.step(int(2 * hz))  # two seconds of flight and landing

st = sim.stats()
sim.save(out)
print(f"toss: {st['ticks']} ticks, max speed {st['max_speed']:.2f}, bbox {st['bbox_min']} .. {st['bbox_max']}, "
      f"state hash {st['state_hash']} -> {out}")
