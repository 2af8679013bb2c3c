"""`import tender`: the Python module against `tender sim` (run by ctest as python.module)."""
import json
import os
import struct
import subprocess
import sys

import numpy as np
import pytest

import tender

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TENDER = os.environ.get("TENDER")
# The seeds' cloth without contact, as a preset file (tests/scenes: a test scene no preset changes)
CLOTH = os.path.join(ROOT, "tests", "scenes", "cloth.json")


sys.path.insert(0, os.path.join(ROOT, "bench"))
import gestures  # noqa: E402 (bench/gestures.py: the hand's gestures as input scripts)
import stretch  # noqa: E402


def cli_hash(*args):
    out = subprocess.run([TENDER, "sim", *args], check=True, capture_output=True, text=True).stdout
    return out.strip().split("state hash ")[-1]


@pytest.mark.skipif(not TENDER, reason="TENDER (the tender program) not set")
def test_same_hash_as_tender_sim():
    sim = tender.Simulation(preset="crumple", backend="cpu")
    sim.step(30)
    assert sim.state_hash() == cli_hash("--backend", "cpu", "--preset", "crumple", "--ticks", "30")
    assert sim.stats()["state_hash"] == sim.state_hash()
    # A preset file, read by the same code as `--preset-file`
    sim = tender.Simulation(preset_file=CLOTH, backend="cpu", cols=8, rows=12)
    sim.step(10)
    assert sim.state_hash() == cli_hash("--backend", "cpu", "--preset-file", CLOTH, "--set", "cols=8", "--set",
                                        "rows=12", "--ticks", "10")


@pytest.mark.skipif(not TENDER, reason="TENDER (the tender program) not set")
def test_params_spelled_as_set():
    sim = tender.Simulation(preset="tender-low", backend="cpu", wind=False, gravity=2.5, iterations=3,
                            pins="corners", damping=0.98)
    sim.step(12)
    assert sim.state_hash() == cli_hash("--backend", "cpu", "--preset", "tender-low", "--set", "wind=off",
                                        "--set", "gravity=2.5", "--set", "iterations=3", "--set",
                                        "pins=corners", "--set", "damping=0.98", "--ticks", "12")


def test_arrays_and_stats():
    sim = tender.Simulation(preset="crumple-low", backend="cpu")
    sim.step(5)
    pos, vel, tri = sim.positions, sim.velocities, sim.triangles
    n = sim.particle_count
    assert pos.shape == (n, 3) and pos.dtype == np.float32
    assert vel.shape == (n, 3) and vel.dtype == np.float32
    assert tri.shape[1] == 3 and tri.dtype == np.int32 and tri.min() >= 0 and tri.max() < n
    st = sim.stats()
    assert st["particles"] == n and st["ticks"] == 5 and st["triangles"] == len(tri)
    assert st["backend"] == "cpu" and st["preset"] == "crumple-low"
    assert np.isclose(np.linalg.norm(vel, axis=1).max(), st["max_speed"], rtol=1e-5)
    assert np.allclose(pos.min(axis=0), st["bbox_min"]) and np.allclose(pos.max(axis=0), st["bbox_max"])
    pos[:] = 0  # a copy: the sheet does not change
    assert sim.positions.any()


def test_grab_move_release_and_reset():
    sim = tender.Simulation(preset="crumple-low", backend="cpu")
    start = sim.positions
    sim.grab(0)
    assert sim.grabbed == 0
    sim.move(1.0, 2.0, 3.0)
    # The contact bounds each substep's step (the grab's too), so a grab moved 5 units at once
    # reaches its target over some ticks
    sim.step(40)
    assert np.allclose(sim.positions[0], [1.0, 2.0, 3.0], atol=1e-4)
    sim.release()
    assert sim.grabbed == -1
    sim.step(2)
    assert sim.grab_ray((0.0, 0.0, 10.0), (0.0, 0.0, -1.0)) in (True, False)
    assert not sim.grab_ray((100.0, 100.0, 100.0), (0.0, 1.0, 0.0))
    sim.release()
    sim.reset()
    assert np.array_equal(sim.positions, start)
    sim.step(3)
    sim.reset(animated=True)
    sim.step(30)  # the 30 frames of the animated reset
    assert np.allclose(sim.positions, start, atol=1e-4)


def test_the_hand_crumples_a_sheet_into_a_ball():
    sim = tender.Simulation(preset="crumple", backend="cpu", cols=20, rows=30, pins="none", wind=False)
    spread = lambda p: float(np.sqrt(((p - p.mean(0)) ** 2).sum(1).mean()))
    flat = spread(sim.positions)
    sim.squeeze(1.0)  # no grab, no hand
    assert sim.closure == 0.0
    sim.grab(15 * 20 + 10)
    sim.squeeze(1.0)
    assert sim.closure == 1.0
    sim.step(120)
    ball = spread(sim.positions)
    assert ball < 0.65 * flat, (ball, flat)
    sim.release()
    assert sim.closure == 0.0
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="squeeze"):
            sim.squeeze(bad)
    fleet = tender.Fleet(2, preset="crumple", backend="cpu", cols=12, rows=16)
    fleet.grab(1, 100)
    fleet.squeeze(1, 1.0)
    fleet.step(30)
    p = fleet.positions
    assert spread(p[1]) < spread(p[0])


def test_set_live_and_rebuild():
    sim = tender.Simulation(preset="tender-low", backend="cpu")
    sim.step(3)
    before = sim.positions
    sim.set("damping", 0.95)  # live: the sheet keeps its state
    sim.set("wind", False)
    assert sim.params["damping"] == "0.95" and sim.params["wind"] == "off"
    assert np.array_equal(sim.positions, before)
    sim.set("gravity", np.float32(1.5))  # NumPy scalars as their Python values
    sim.set("iterations", np.int64(3))
    sim.set("collision", np.bool_(False))
    assert (sim.params["gravity"], sim.params["iterations"], sim.params["collision"]) == ("1.5", "3", "off")
    sim.set("cols", 10)  # rebuilds
    assert sim.positions.shape[0] == 10 * int(sim.params["rows"])
    sim.step(2)


def test_bad_input_raises():
    with pytest.raises(KeyError, match="unknown parameter 'nope'"):
        tender.Simulation(backend="cpu", nope=1)
    with pytest.raises(ValueError, match="unknown preset 'nope'"):
        tender.Simulation(preset="nope", backend="cpu")
    with pytest.raises(ValueError, match="^preset and preset_file: give one, not both$"):
        tender.Simulation(preset="tender", preset_file=CLOTH)
    with pytest.raises(ValueError, match="^preset_file: /nonexistent.json: cannot read: "):
        tender.Fleet(2, preset_file="/nonexistent.json")
    with pytest.raises(ValueError, match="unknown backend"):
        tender.Simulation(backend="metal")
    with pytest.raises(ValueError, match="^gravity: "):
        tender.Simulation(backend="cpu", gravity=float("nan"))
    with pytest.raises(ValueError, match="^gravity: "):
        tender.Simulation(backend="cpu", gravity=float("inf"))
    with pytest.raises(ValueError, match="^cols: "):
        tender.Simulation(backend="cpu", cols=-3)
    with pytest.raises(TypeError, match="^cols: expected a bool, an int, a float or a str, got list"):
        tender.Simulation(backend="cpu", cols=[1])
    sim = tender.Simulation(preset="crumple-low", backend="cpu")
    with pytest.raises(ValueError, match="does not exist"):
        sim.grab(sim.particle_count)
    with pytest.raises(ValueError, match="does not exist"):
        sim.grab(-1)
    with pytest.raises(ValueError, match="ticks"):
        sim.step(-1)
    with pytest.raises(ValueError, match="out of range"):
        sim.move(float("nan"), 0, 0)
    with pytest.raises(ValueError, match="out of range"):
        sim.move(1e7, 0, 0)
    with pytest.raises(ValueError):
        sim.grab_ray((0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError):
        sim.grab_ray((0, 0), (0, 0, 1))
    with pytest.raises(ValueError):
        sim.grab_ray((0, 0, "x"), (0, 0, 1))
    with pytest.raises(ValueError, match="out of range"):
        sim.grab_ray((0, 0, float("inf")), (0, 0, 1))
    with pytest.raises(KeyError):
        sim.set("nope", 1)
    with pytest.raises(ValueError, match="^iterations: "):
        sim.set("iterations", 0)
    with pytest.raises(ValueError):
        sim.save("out.xyz")
    # What a message quotes is escaped as the command line prints it, not cut at a NUL
    with pytest.raises(ValueError, match=r"^unknown preset 'a\\x00b' \(one of"):
        tender.Simulation(preset="a\x00b", backend="cpu")
    with pytest.raises(ValueError, match=r"a\\x00b"):
        sim.set("pins", "a\x00b")
    with pytest.raises(KeyError) as unknown:  # (a KeyError's str() is its message's repr)
        sim.set("a\x00b", 1)
    assert unknown.value.args[0].startswith("unknown parameter 'a\\x00b'")
    # The sheet is unchanged and still runs.
    sim.step(1)
    assert sim.stats()["nan_count"] == 0


def test_save_ply_and_glb(tmp_path):
    sim = tender.Simulation(preset="crumple-low", backend="cpu")
    sim.step(3)
    sim.save(str(tmp_path / "a.ply"))
    sim.save(str(tmp_path / "a.glb"))
    sim.save(str(tmp_path / "a.gltf"))
    ply = (tmp_path / "a.ply").read_bytes()
    assert ply.startswith(b"ply\n") and b"element vertex %d" % sim.particle_count in ply
    glb = (tmp_path / "a.glb").read_bytes()
    magic, version, length = struct.unpack("<4sII", glb[:12])
    assert magic == b"glTF" and version == 2 and length == len(glb)
    assert json.loads((tmp_path / "a.gltf").read_text())["asset"]["version"] == "2.0"
    assert sorted(os.listdir(tmp_path)) == ["a.glb", "a.gltf", "a.ply"]  # no temporary left
    with pytest.raises(OSError, match="cannot write .*does not exist"):
        sim.save(str(tmp_path / "missing" / "a.glb"))
    # The whole path, escaped, and nothing written (not the file named by the part before the NUL)
    with pytest.raises(OSError, match=r"cannot write '.*/a\\x00b\.glb': a path cannot hold a NUL"):
        sim.save(str(tmp_path / "a\x00b.glb"))
    assert sorted(os.listdir(tmp_path)) == ["a.glb", "a.gltf", "a.ply"]


def test_presets_and_devices():
    assert tender.presets()[:2] == ["tender", "crumple"]
    devices = tender.devices()
    assert isinstance(devices, list)
    for d in devices:
        assert {"name", "type"} <= set(d)


def test_gpu_on_lavapipe():
    if not tender.vulkan_built():
        with pytest.raises(RuntimeError):
            tender.Simulation(backend="gpu")
        return
    if not any(d["usable"] for d in tender.devices()):
        pytest.skip("no usable Vulkan device")
    gpu = tender.Simulation(preset="crumple-low", backend="gpu")
    cpu = tender.Simulation(preset="crumple-low", backend="cpu")
    gpu.step(5)
    cpu.step(5)
    assert gpu.backend == "gpu" and gpu.state_hash() == cpu.state_hash()
    assert "gpu_ms_per_pass" in gpu.stats()


def test_gpu_bad_device():
    if not tender.vulkan_built():
        pytest.skip("no Vulkan in this build")
    with pytest.raises(RuntimeError):
        tender.Simulation(backend="gpu", device=99)


def test_toss_example(tmp_path):
    out = tmp_path / "toss.glb"
    r = subprocess.run([sys.executable, os.path.join(ROOT, "examples", "toss.py"), str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:4] == b"glTF"


# (it tears in its second step; the last steps run let go)
YANK = "0 grab particle 186\n1 move 4 -4 6\n12 release\n"


def fleet_sheets():
    return [{"damping": 0.98}, {"gravity": 7.5, "pins": "corners"}, {"tear_factor": 0.0},
            {"wind_kind": "noise", "wind_strength": 1.5}, {"stiffness": 0.8, "iterations": 3}]


# The GPU fleet's per-colour passes, and sheets too large for the fused tick, are the C++ fleet
# tests' (tests/gpu/fleet_test.cpp); here the module's Fleet on each backend.
@pytest.mark.parametrize("backend,cols,rows", [("cpu", 12, 16), ("gpu", 12, 16)])
def test_fleet_sheets_match_their_runs_alone(backend, cols, rows):
    if backend == "gpu" and not (tender.vulkan_built() and any(d["usable"] for d in tender.devices())):
        pytest.skip("no usable Vulkan device")
    sheets = fleet_sheets()
    scripts = [YANK if i % 2 == 0 else "" for i in range(len(sheets))]
    # The seeds' cloth (a fleet with contact: test_the_hand_crumples_a_sheet_into_a_ball)
    fleet = tender.Fleet(sheets, preset_file=CLOTH, backend=backend, cols=cols, rows=rows, scripts=scripts)
    fleet.step(20)
    assert len(fleet) == 5 and fleet.backend == backend
    pos = fleet.positions
    assert pos.shape == (5, cols * rows, 3) and pos.dtype == np.float32
    assert fleet.velocities.shape == pos.shape
    hashes = fleet.state_hashes()
    torn = [fleet.stats(i)["torn"] for i in range(5)]
    for i, extra in enumerate(sheets):
        sim = tender.Simulation(preset_file=CLOTH, backend=backend, cols=cols, rows=rows, **extra)
        if scripts[i]:
            for step in range(20):
                if step == 0:
                    sim.grab(186)
                if step == 1:
                    sim.move(4, -4, 6)
                if step == 12:
                    sim.release()
                sim.step(1)
        else:
            sim.step(20)
        assert hashes[i] == sim.state_hash(), "sheet %d" % i
        assert np.array_equal(pos[i], sim.positions)
        assert fleet.params(i)["damping"] == sim.params["damping"]
    # The yank tears at the default tear factor, and nothing tears with tearing off
    assert torn[0] > 0 and torn[2] == 0
    assert [s["state_hash"] for s in fleet.stats()] == hashes


def test_fleet_bad_input_raises():
    with pytest.raises(ValueError):
        tender.Fleet(0)
    with pytest.raises(ValueError):
        tender.Fleet([{"cols": 12}, {"cols": 13}])  # different grids
    with pytest.raises(KeyError):
        tender.Fleet([{"no_such_key": 1}])
    with pytest.raises(ValueError):
        tender.Fleet(2, scripts=["0 grab particle 99999\n", ""])
    with pytest.raises(ValueError):
        tender.Fleet(2, scripts=[""])
    # A fleet sizes contact's buffers when its sheets are made: a script may not turn it on later
    # (refused when the fleet is made, on every backend, not after some ticks on the GPU)
    with pytest.raises(ValueError, match=r"^scripts\[0\]: tick 2: set contact_factor: "):
        tender.Fleet(2, preset_file=CLOTH, backend="cpu", cols=8, rows=8,
                     scripts=["0 grab particle 27\n2 set contact_factor 0.5\n", "0 grab particle 27\n"])
    fleet = tender.Fleet(2, cols=8, rows=8)
    with pytest.raises(IndexError):
        fleet.grab(2, 0)
    with pytest.raises(ValueError):
        fleet.grab(0, 64)


def test_types_and_write_errors_raise_as_the_cli_says(tmp_path):
    # A count too large for any integer type, a key that is not a name, a value of the wrong type
    with pytest.raises(ValueError, match="^sheets: expected 1 to 65535, got 1208925819614629174706176$"):
        tender.Fleet(2**80)
    with pytest.raises(TypeError, match=r"^sheets\[0\]: keys are parameter names \(str\), got int$"):
        tender.Fleet([{1: 1}])
    with pytest.raises(TypeError, match=r"^sheets\[1\]: expected a dict, got int$"):
        tender.Fleet([{}, 3])
    with pytest.raises(TypeError, match="^sheets: expected a count or a list of dicts, got bool$"):
        tender.Fleet(True)
    # One rule with preset files: whole numbers for whole keys, True/False for on/off keys
    with pytest.raises(TypeError, match="^cols: expected a whole number, got 8.0$"):
        tender.Simulation(backend="cpu", cols=8.0)
    with pytest.raises(TypeError, match="^wind: expected true or false, got 1$"):
        tender.Simulation(backend="cpu", wind=1)
    with pytest.raises(TypeError, match="^pins: expected a name, got true$"):
        tender.Simulation(backend="cpu", pins=True)
    assert tender.Simulation(backend="cpu", cols=8, rows=8, damping=1, wind="off").params["wind"] == "off"
    sim = tender.Simulation(backend="cpu", cols=8, rows=8)
    with pytest.raises(ValueError, match="^an output path is empty$"):
        sim.save("")
    with pytest.raises(OSError, match="^cannot write '/dev/full': No space left on device$"):
        sim.save("/dev/full")
    with pytest.raises(OSError, match="is a folder"):
        sim.save(str(tmp_path))
    # Truth values are True or False: NaN and None are refused, and nothing changes
    wind, paused = sim.wind, sim.paused
    with pytest.raises(TypeError, match="^paused: expected True or False, got float$"):
        sim.paused = float("nan")
    with pytest.raises(TypeError, match="^wind: expected True or False, got NoneType$"):
        sim.wind = None
    with pytest.raises(TypeError, match="^pins: expected True or False, got int$"):
        sim.pins = 1
    assert (sim.wind, sim.paused) == (wind, paused)
    sim.paused = True
    assert sim.paused


def test_a_fleet_too_large_for_memory_is_refused_up_front():
    # 60000 sheets of 64x64 need about 229 GB: refused in words before anything is allocated.
    with pytest.raises(ValueError, match="^a batch of 60000 64x64 sheets needs about [0-9]+ MiB on the cpu backend; "):
        tender.Fleet(60000, cols=64, rows=64)


def test_threads_read_arrays_before_numpy_is_imported():
    # Two threads reading positions first thing in a fresh interpreter (NumPy not yet imported by
    # the script) finish: no deadlock between the GIL and NumPy's import.
    code = """
import threading, tender
sims = [tender.Simulation(backend="cpu", cols=8, rows=8) for _ in range(2)]
out = []
threads = [threading.Thread(target=lambda s=s: out.append(s.positions.shape)) for s in sims]
[t.start() for t in threads]
[t.join() for t in threads]
assert out == [(64, 3), (64, 3)], out
print("ok")
"""
    for _ in range(3):
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


def test_set_of_a_layout_key_rebuilds_the_sheet_as_a_script_does(tmp_path):
    # tilt decides where the sheet is: setting it rebuilds the sheet at rest, as a fresh one
    sim = tender.Simulation(backend="cpu", cols=8, rows=8)
    sim.step(5)
    sim.set("tilt", 45)
    fresh = tender.Simulation(backend="cpu", cols=8, rows=8, tilt=45)
    assert (sim.positions == fresh.positions).all()
    # Python's set is a script's set event: `tender sim` with it at tick 5 ends in the same state
    sim.step(15)
    script = tmp_path / "tilt.txt"
    script.write_text("5 set tilt 45\n")
    assert cli_hash("--backend", "cpu", "--set", "cols=8", "--set", "rows=8", "--script", str(script),
                    "--ticks", "20") == sim.state_hash()


def test_gesture_scripts_replay_their_gestures(tmp_path):
    # Gestures of bench/stretch.py, recorded as they run on a small crumple sheet, replay through
    # `tender sim --script` to the module's state (the GPU kit's real-time check runs the scripts).
    # Three hold every event a gesture sends: grab, move, squeeze (crumple, fast) and release.
    for name, gesture in [g for g in stretch.GESTURES if g[0] in ("crumple", "fast", "yank")]:
        sc, keys, text = gestures.record("crumple", gesture, {"cols": 10, "rows": 15}, True)
        script = tmp_path / f"{name}.txt"
        script.write_text(text)
        assert cli_hash("--backend", "cpu", *keys.split(), "--script", str(script)) == sc.sim.state_hash(), name


def test_bench_gestures_are_what_gestures_py_writes(tmp_path):
    # bench/gestures/ holds the scripts of the presets' gestures as bench/gestures.py writes them
    written = os.path.join(ROOT, "bench", "gestures")
    for preset in ("crumple", "tender"):
        for name, gesture in stretch.GESTURES:
            with open(os.path.join(written, f"{preset}-{name}.txt")) as f:
                assert f.read() == gestures.record(preset, gesture, {}, False)[2], f"{preset}-{name}"
