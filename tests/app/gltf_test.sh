#!/usr/bin/env bash
# glTF export of `tender sim`: .glb and .gltf of the end state, a numbered sequence (--out DIR/)
# and one animated file (--frames-every K --out FILE.glb). Every file is read back here (counts,
# index ranges, accessor bounds, the embedded PNG), checked by the Khronos glTF-Validator when
# tools/setup installed it (npm), and imported by Blender when it is installed. Bad input exits 2
# with one line and writes nothing.
set -u
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
passed=0
ok() { echo "ok: $*"; passed=$((passed + 1)); }

# A 16 x 24 sheet yanked by its free corner until it tears.
sim=(sim --backend cpu "${cloth[@]}" --set cols=16 --set rows=24 --set substeps=4 --set iterations=2)
printf '0 grab particle 383\n1 move 0 -40 4\n' >"$tmp/yank.txt"
run=("${sim[@]}" --script "$tmp/yank.txt" --ticks 24)

mkdir -p "$tmp/seq" "$tmp/bad"
touch "$tmp/file"
expect_bad "${run[@]}" --out "$tmp/bad/x.obj"
expect_bad "${run[@]}" --out "$tmp/bad/x.glb.txt"
expect_bad "${run[@]}" --frames-every 0 --out "$tmp/bad/"
expect_bad "${run[@]}" --frames-every -3 --out "$tmp/bad/"
expect_bad "${run[@]}" --frames-every abc --out "$tmp/bad/a.glb"
expect_bad "${run[@]}" --frames-every 4
expect_bad "${run[@]}" --frames-every 4 --out "$tmp/bad/x.ply"
expect_bad "${run[@]}" --out "$tmp/bad/"
expect_bad "${run[@]}" --frames-every 4 --out "$tmp/missing/"
expect_bad "${run[@]}" --frames-every 4 --out "$tmp/file/"
expect_bad "${run[@]}" --out /nonexistent/dir/x.glb
expect_bad "${run[@]}" --frames-every 4 --out "$tmp/bad/" --stats /dev/full
expect_bad "${run[@]}" --frames-every 4 --out "$tmp/bad/" --stats "$tmp/bad/frame_000002.glb"
expect_bad "${sim[@]}" --ticks 100000 --frames-every 1 --out "$tmp/bad/anim.glb"
if [ -z "$(ls -A "$tmp/bad")" ]; then ok "failed runs wrote nothing"; else fail "failed runs left $(ls "$tmp/bad")"; fi

# Good runs: the end state, the sequence, the animation (frames at ticks 0, 10, 20 and 24).
good() { "$T" "$@" >"$tmp/out" 2>"$tmp/err" && ok "tender $*" || fail "tender $* -> $(cat "$tmp/err")"; }
good "${run[@]}" --out "$tmp/end.glb" --stats "$tmp/end.json"
good "${run[@]}" --out "$tmp/end.gltf"
good "${run[@]}" --frames-every 10 --out "$tmp/seq/"
good "${run[@]}" --frames-every 10 --out "$tmp/anim.glb"
good "${run[@]}" --frames-every 10 --out "$tmp/anim.gltf"
good "${run[@]}" --out "$tmp/end.ply"
files=("$tmp/end.glb" "$tmp/end.gltf" "$tmp/seq/"frame_*.glb "$tmp/anim.glb" "$tmp/anim.gltf")
if [ "$(ls "$tmp/seq")" = "$(printf 'frame_%06d.glb\n' 0 1 2 3)" ]; then
  ok "sequence: $(ls "$tmp/seq" | tr '\n' ' ')"
else
  fail "sequence folder holds: $(ls -a "$tmp/seq" | tr '\n' ' ')"
fi
if ls -a "$tmp" "$tmp/seq" | grep -q '\.tmp\.'; then fail "temporary files left"; else ok "no temporary files left"; fi

# Read every file back (a reader independent of tinygltf): the structure, counts, index ranges,
# accessor bounds, the embedded PNG, the corners across a crease (their triangle's normal); the
# animation's frames; the end state against the stats.
if python3 - "$tmp" <<'PY'; then ok "every file reads back consistently"; else fail "read-back"; fi
import base64, json, math, struct, sys, os
tmp = sys.argv[1]

def load(path):
    data = open(path, "rb").read()
    if path.endswith(".glb"):
        magic, version, length = struct.unpack_from("<4sII", data, 0)
        assert magic == b"glTF" and version == 2 and length == len(data), (path, magic, version, length)
        jlen, jtype = struct.unpack_from("<II", data, 12)
        assert jtype == 0x4E4F534A
        doc = json.loads(data[20:20 + jlen])
        off = 20 + jlen
        blen, btype = struct.unpack_from("<II", data, off)
        assert btype == 0x004E4942
        return doc, data[off + 8:off + 8 + blen]
    doc = json.loads(data)
    uri = doc["buffers"][0]["uri"]
    assert uri.startswith("data:application/octet-stream;base64,"), uri[:40]
    return doc, base64.b64decode(uri.split(",", 1)[1])

PARTICLES = 16 * 24
SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}

def values(doc, binary, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    n = a["count"] * SIZES[a["type"]]
    fmt = {5126: "f", 5125: "I"}[a["componentType"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    assert start + 4 * n <= v.get("byteOffset", 0) + v["byteLength"] <= len(binary)
    flat = struct.unpack_from("<%d%s" % (n, fmt), binary, start)
    k = SIZES[a["type"]]
    return [flat[i:i + k] for i in range(0, n, k)]

def check(path, frames):
    doc, binary = load(path)
    assert doc["asset"]["version"] == "2.0"
    prim = doc["meshes"][0]["primitives"][0]
    pos = values(doc, binary, prim["attributes"]["POSITION"])
    n = len(pos)
    # A vertex per particle, then one per triangle corner across a crease (its triangle's normal)
    assert n >= PARTICLES, n
    for attr in ("NORMAL", "TEXCOORD_0"):
        assert doc["accessors"][prim["attributes"][attr]]["count"] == n, attr
    normals = values(doc, binary, prim["attributes"]["NORMAL"])
    for nrm in normals:
        assert abs(math.sqrt(sum(c * c for c in nrm)) - 1) < 1e-4, nrm
    def bounds(index):
        a, vals = doc["accessors"][index], values(doc, binary, index)
        for k in range(3):
            assert math.isclose(a["min"][k], min(p[k] for p in vals), rel_tol=1e-6), (path, a["min"])
            assert math.isclose(a["max"][k], max(p[k] for p in vals), rel_tol=1e-6), (path, a["max"])
    bounds(prim["attributes"]["POSITION"])
    idx = [i[0] for i in values(doc, binary, prim["indices"])]
    assert len(idx) % 3 == 0 and idx and max(idx) < n, (len(idx), max(idx))
    ia = doc["accessors"][prim["indices"]]
    assert ia["min"] == [min(idx)] and ia["max"] == [max(idx)]
    particle_at = {p: i for i, p in enumerate(pos[:PARTICLES])}
    particle = list(range(PARTICLES)) + [particle_at[p] for p in pos[PARTICLES:]]  # a corner's own: its particle's place
    own = 0
    for t in range(0, len(idx), 3):
        for c in range(3):
            if idx[t + c] >= PARTICLES:  # the corner's own vertex: its triangle's normal
                own += 1
                a, b, d = (pos[idx[t + k]] for k in range(3))
                e1 = [b[k] - a[k] for k in range(3)]
                e2 = [d[k] - a[k] for k in range(3)]
                f = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
                fl = math.sqrt(sum(x * x for x in f))
                assert all(abs(f[k] / fl - normals[idx[t + c]][k]) < 1e-4 for k in range(3)), (path, t)
    assert own == n - PARTICLES, (own, n)  # each used by one corner
    idx = [particle[i] for i in idx]  # the triangles by their particles
    mat = doc["materials"][prim["material"]]
    assert mat["doubleSided"] is True
    pbr = mat["pbrMetallicRoughness"]
    assert pbr["metallicFactor"] == 0 and abs(pbr["roughnessFactor"] - 0.7) < 1e-6, pbr
    img = doc["images"][doc["textures"][pbr["baseColorTexture"]["index"]]["source"]]
    assert img["mimeType"] == "image/png"
    v = doc["bufferViews"][img["bufferView"]]
    png = binary[v.get("byteOffset", 0):v.get("byteOffset", 0) + v["byteLength"]]
    assert png[:8] == b"\x89PNG\r\n\x1a\n", png[:8]
    w, h = struct.unpack(">II", png[16:24])
    assert (w, h) == (512, 768), (w, h)
    targets = prim.get("targets", [])
    assert len(targets) == frames - 1, (path, len(targets))
    for t in targets:
        bounds(t["POSITION"])
    if frames > 1:
        anim = doc["animations"][0]
        s = anim["samplers"][anim["channels"][0]["sampler"]]
        assert s["interpolation"] == "STEP" and anim["channels"][0]["target"]["path"] == "weights"
        times = [t[0] for t in values(doc, binary, s["input"])]
        assert len(times) == frames and times == sorted(times) and times[0] == 0, times
        w = values(doc, binary, s["output"])
        assert len(w) == frames * (frames - 1)
    return doc, binary, pos, idx

stats = json.load(open(os.path.join(tmp, "end.json")))
for name in ("end.glb", "end.gltf"):
    doc, binary, pos, idx = check(os.path.join(tmp, name), 1)
    assert len(idx) == 3 * stats["triangles"], (len(idx), stats["triangles"])
    assert stats["torn"] > 0 and stats["triangles"] < 2 * 15 * 23, stats
    for k in range(3):
        assert math.isclose(min(p[k] for p in pos), stats["bbox_min"][k], rel_tol=1e-5, abs_tol=1e-5)
seq = [check(os.path.join(tmp, "seq", "frame_%06d.glb" % k), 1) for k in range(4)]
assert len(seq[0][3]) == 3 * 2 * 15 * 23 and len(seq[3][3]) == 3 * stats["triangles"]  # each frame its own triangles
assert seq[3][2] == check(os.path.join(tmp, "end.glb"), 1)[2]  # the last frame is the end state
for name in ("anim.glb", "anim.gltf"):
    doc, binary, pos, idx = check(os.path.join(tmp, name), 4)
    # frame 0's particles, the last frame's triangles
    assert pos[:PARTICLES] == seq[0][2][:PARTICLES] and idx == seq[3][3]
    prim = doc["meshes"][0]["primitives"][0]
    last = values(doc, binary, prim["targets"][2]["POSITION"])
    for p, d, e in zip(pos[:PARTICLES], last, seq[3][2][:PARTICLES]):
        for k in range(3):
            assert abs(p[k] + d[k] - e[k]) < 1e-4 * max(1, abs(e[k])), (p, d, e)
print("read back:", len(seq[3][3]) // 3, "triangles at the end,", stats["torn"], "constraints torn,",
      len(seq[3][2]) - PARTICLES, "corners across a crease")
PY

# A script's set event that rebuilds the sheet with another grid: the end state's texture
# coordinates are those of the new sheet (the right column at u = 1, the bottom row at v = 1).
printf '5 set cols 9\n5 set rows 7\n' >"$tmp/regrid.txt"
"$T" sim --backend cpu --set cols=16 --set rows=24 --ticks 10 --script "$tmp/regrid.txt" --out "$tmp/regrid.glb" \
  >/dev/null || fail "a regridded run's glTF"
python3 - "$tmp/regrid.glb" <<'PY' && ok "a rebuilt sheet's glTF has its own texture coordinates" || fail "regrid UVs"
import json, struct, sys
data = open(sys.argv[1], "rb").read()
jlen = struct.unpack_from("<I", data, 12)[0]
doc = json.loads(data[20:20 + jlen])
binary = data[20 + jlen + 8:]
a = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]]
v = doc["bufferViews"][a["bufferView"]]
start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
uv = struct.unpack_from("<%df" % (2 * a["count"]), binary, start)
assert a["count"] == 63, a["count"]
us, vs = uv[0::2], uv[1::2]
assert (min(us), max(us), min(vs), max(vs)) == (0.0, 1.0, 0.0, 1.0), (min(us), max(us), min(vs), max(vs))
PY

# Taking frames leaves the run as it is; the GPU backend (where there is a Vulkan device) writes
# the CPU's bytes.
"$T" "${run[@]}" | grep -o 'state hash [0-9a-f]*' >"$tmp/hash_plain"
"$T" "${run[@]}" --frames-every 3 --out "$tmp/anim3.glb" | grep -o 'state hash [0-9a-f]*' >"$tmp/hash_frames"
if [ -s "$tmp/hash_plain" ] && cmp -s "$tmp/hash_plain" "$tmp/hash_frames"; then
  ok "frames leave the $(cat "$tmp/hash_plain")"
else
  fail "frames change the run: $(cat "$tmp/hash_plain") vs $(cat "$tmp/hash_frames")"
fi
if "$T" devices >/dev/null 2>&1; then
  gpu_run=("${run[@]}")
  gpu_run[2]=gpu # --backend gpu
  if "$T" "${gpu_run[@]}" --frames-every 10 --out "$tmp/anim_gpu.glb" >/dev/null 2>"$tmp/err" &&
    cmp -s "$tmp/anim.glb" "$tmp/anim_gpu.glb"; then
    ok "the GPU backend writes the CPU's animated file"
  else
    fail "GPU animated file differs from the CPU's: $(cat "$tmp/err")"
  fi
else
  echo "skip: no Vulkan device for the GPU comparison"
fi

# The Khronos glTF-Validator (npm package gltf-validator; tools/setup installs it globally).
node_path=""
command -v npm >/dev/null && node_path=$(npm root -g 2>/dev/null)
if command -v node >/dev/null; then
  NODE_PATH="$node_path" node "$here/gltf_validate.js" "${files[@]}" >"$tmp/validator.txt" 2>&1
  rc=$?
  sed 's/^/  /' "$tmp/validator.txt"
  case $rc in
    0) ok "gltf-validator: no errors, no warnings in ${#files[@]} files" ;;
    77) echo "skip: gltf-validator not installed (tools/setup installs it with npm)" ;;
    *) fail "gltf-validator" ;;
  esac
else
  echo "skip: no node for gltf-validator"
fi

# Blender (optional): its glTF importer reads the static and the animated file.
if command -v blender >/dev/null; then
  cat >"$tmp/import.py" <<'PY'
import sys
try:
    import numpy
except ImportError:
    print("SKIP: no numpy for Blender's glTF importer")
    sys.exit(0)
if not hasattr(numpy, "bool"):
    numpy.bool = bool  # Blender 3.4's importer uses numpy.bool, gone from newer numpy
import bpy
for path in sys.argv[sys.argv.index("--") + 1:]:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    assert len(meshes) == 1, path
    mesh = meshes[0]
    assert len(mesh.data.polygons) > 0, path
    mat = mesh.active_material
    assert mat is not None and not mat.use_backface_culling, path
    assert any(tuple(i.size) == (512, 768) for i in bpy.data.images), path  # the receipt
    keys = mesh.data.shape_keys
    if "anim" in path:
        assert keys and len(keys.key_blocks) == 4, path  # the basis and three frames
        action = keys.animation_data.action if keys.animation_data else None
        assert action is not None and len(action.fcurves) == 3, path
    print("imported", path, len(mesh.data.vertices), "vertices,", len(mesh.data.polygons), "triangles,",
          len(keys.key_blocks) if keys else 0, "shape keys")
PY
  timeout 120 blender --background --factory-startup --python-exit-code 1 --python "$tmp/import.py" -- \
    "$tmp/end.glb" "$tmp/anim.glb" >"$tmp/blender.txt" 2>&1
  if grep -q "^SKIP" "$tmp/blender.txt"; then
    echo "skip: $(grep '^SKIP' "$tmp/blender.txt")"
  elif grep -q "imported .*anim.glb" "$tmp/blender.txt"; then
    ok "blender imports the files: $(grep imported "$tmp/blender.txt" | tr '\n' ' ')"
  else
    fail "blender import: $(tail -5 "$tmp/blender.txt")"
  fi
else
  echo "skip: blender not installed"
fi

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
