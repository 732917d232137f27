#!/usr/bin/env python3
"""Builds scenes/dragon/dragon.gltf from the Stanford dragon GLB (100k triangles).

The dragon's binary chunk is written unchanged to scenes/dragon/dragon.bin; the scene adds a
floor, a square area light above, a camera and NUSSELT_brdf materials. Usage:
  tools/make_dragon_scene.py stanford-dragon-100k.glb
(the GLB comes from the project's asset set; its licence is in scenes/dragon/LICENSE.md).
"""
import base64, json, math, struct, sys
from pathlib import Path

glb = Path(sys.argv[1]).read_bytes()
magic, version, length = struct.unpack_from("<III", glb, 0)
assert magic == 0x46546C67 and version == 2
jlen, jtype = struct.unpack_from("<II", glb, 12)
gltf = json.loads(glb[20:20 + jlen])
blen, btype = struct.unpack_from("<II", glb, 20 + jlen)
binary = glb[28 + jlen:28 + jlen + blen]
out = Path(__file__).resolve().parent.parent / "scenes" / "dragon"
out.mkdir(parents=True, exist_ok=True)
(out / "dragon.bin").write_bytes(binary[:gltf["buffers"][0]["byteLength"]])
gltf["buffers"][0]["uri"] = "dragon.bin"

# Extra geometry: floor (y = 0) and light (y = 16), each a quad of two triangles.
def quad(y, half, down):
    p = [(-half, y, -half), (half, y, -half), (half, y, half), (-half, y, half)]
    n = (0.0, -1.0 if down else 1.0, 0.0)
    idx = [0, 1, 2, 0, 2, 3] if down else [0, 2, 1, 0, 3, 2]
    return p, [n] * 4, idx

extra = b""
accessors, views = gltf["accessors"], gltf["bufferViews"]
meshes = gltf["meshes"]
def add_mesh(name, quad_data, material):
    global extra
    p, n, idx = quad_data
    base = len(extra)
    extra += b"".join(struct.pack("<3f", *v) for v in p)
    extra += b"".join(struct.pack("<3f", *v) for v in n)
    extra += struct.pack("<6I", *idx)
    first = len(views)
    views.extend([{"buffer": 1, "byteOffset": base, "byteLength": 48},
              {"buffer": 1, "byteOffset": base + 48, "byteLength": 48},
              {"buffer": 1, "byteOffset": base + 96, "byteLength": 24}])
    xs = [v[0] for v in p]; ys = [v[1] for v in p]; zs = [v[2] for v in p]
    a = len(accessors)
    accessors.extend([{"bufferView": first, "componentType": 5126, "count": 4, "type": "VEC3",
                   "min": [min(xs), min(ys), min(zs)], "max": [max(xs), max(ys), max(zs)]},
                  {"bufferView": first + 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": first + 2, "componentType": 5125, "count": 6, "type": "SCALAR"}])
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": a, "NORMAL": a + 1},
                                                 "indices": a + 2, "material": material, "mode": 4}]})
    return len(meshes) - 1

gltf["materials"] = [
    {"name": "dragon", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0},
     "extensions": {"NUSSELT_brdf": {"model": "lambert", "params": {"rho": [0.75, 0.72, 0.6]}}}},
    {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0},
     "extensions": {"NUSSELT_brdf": {"model": "lambert", "params": {"rho": [0.5, 0.5, 0.5]}}}},
    {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
     "emissiveFactor": [1.0, 1.0, 1.0], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}}},
]
floor = add_mesh("floor", quad(0.0, 40.0, False), 1)
light = add_mesh("light", quad(18.0, 5.0, True), 2)
gltf["buffers"].append({"byteLength": len(extra),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(extra).decode()})
# Camera: in front of the dragon, slightly above, looking at its centre.
eye, target = (0.0, 7.0, 24.0), (0.0, 4.5, 0.0)
pitch = math.atan2(target[1] - eye[1], eye[2] - target[2])
gltf["cameras"] = [{"name": "front", "type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}]
gltf["nodes"] += [{"name": "floor", "mesh": floor}, {"name": "light", "mesh": light},
                  {"name": "front", "camera": 0, "translation": list(eye),
                   "rotation": [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]}]
gltf["scenes"][0]["nodes"] = list(range(len(gltf["nodes"])))
gltf["extensionsUsed"] = ["NUSSELT_brdf", "KHR_materials_emissive_strength"]
gltf["asset"]["generator"] = "nusselt tools/make_dragon_scene.py"
(out / "dragon.gltf").write_text(json.dumps(gltf, indent=1) + "\n")
print("wrote", out / "dragon.gltf", "and", out / "dragon.bin")
