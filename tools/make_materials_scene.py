#!/usr/bin/env python3
"""Writes scenes/materials/materials.gltf: one sphere per reflectance model (20), each with the
model's default parameters (the catalogue's typical set), on a grey floor under one square area
light and a little fill light, seen by one camera. Usage: tools/make_materials_scene.py"""
import base64, json, math, struct
from pathlib import Path

MODELS = ["lambert", "phong_specular", "phong", "lewis", "blinn",
          "torrance_sparrow", "ward", "ashikhmin_shirley", "lafortune", "minnaert",
          "oren_nayar", "schlick", "strauss", "beard_maxwell", "htsg",
          "poulin_fournier", "coupled", "mirror", "dielectric", "gltf_pbr"]
COLS, ROWS, SPACING, RADIUS = 5, 4, 2.4, 1.0

def uv_sphere(nu=48, nv=24):
    pos, nrm, idx = [], [], []
    for j in range(nv + 1):
        v = math.pi * j / nv
        for i in range(nu + 1):
            u = 2 * math.pi * i / nu
            n = (math.sin(v) * math.cos(u), math.cos(v), math.sin(v) * math.sin(u))
            pos.append(n); nrm.append(n)
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i; b = a + nu + 1
            idx += [a, a + 1, b, a + 1, b + 1, b]   # counter-clockwise seen from outside
    return pos, nrm, idx

def quad(half, y, down):
    p = [(-half, y, -half), (half, y, -half), (half, y, half), (-half, y, half)]
    n = [(0.0, -1.0 if down else 1.0, 0.0)] * 4
    return p, n, ([0, 1, 2, 0, 2, 3] if down else [0, 2, 1, 0, 3, 2])

blob = bytearray(); views = []; accessors = []; meshes = []
def add_mesh(name, geo, material):
    p, n, idx = geo
    first = len(accessors)
    for data, kind in ((p, "VEC3"), (n, "VEC3")):
        off = len(blob); blob.extend(b"".join(struct.pack("<3f", *v) for v in data))
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off})
        acc = {"bufferView": len(views) - 1, "componentType": 5126, "count": len(data), "type": kind}
        if kind == "VEC3" and data is p:
            acc["min"] = [min(v[k] for v in data) for k in range(3)]; acc["max"] = [max(v[k] for v in data) for k in range(3)]
        accessors.append(acc)
    off = len(blob); blob.extend(struct.pack("<%dI" % len(idx), *idx))
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"})
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": first, "NORMAL": first + 1},
                                                 "indices": first + 2, "material": material}]})
    return len(meshes) - 1

materials = [{"name": m, "extensions": {"NUSSELT_brdf": {"model": m, "params": {}}}} for m in MODELS]
materials.append({"name": "floor", "extensions": {"NUSSELT_brdf": {"model": "lambert", "params": {"rho": [0.35, 0.35, 0.35]}}}})
materials.append({"name": "light", "emissiveFactor": [1.0, 0.95, 0.85],
                  "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 30.0},
                                 "NUSSELT_brdf": {"model": "lambert", "params": {"rho": 0.0}}}})
sphere = uv_sphere()
nodes = []
for k, m in enumerate(MODELS):
    mesh = add_mesh(m, sphere, k)
    col, row = k % COLS, k // COLS
    nodes.append({"name": m, "mesh": mesh,
                  "translation": [(col - (COLS - 1) / 2) * SPACING, RADIUS, (row - (ROWS - 1) / 2) * SPACING]})
nodes.append({"name": "floor", "mesh": add_mesh("floor", quad(30.0, 0.0, False), len(MODELS))})
nodes.append({"name": "light", "mesh": add_mesh("light", quad(2.5, 12.0, True), len(MODELS) + 1),
              "translation": [-3.0, 0.0, 4.0]})
# Camera: above and in front, looking down at the grid.
eye, target = (0.0, 9.0, 13.5), (0.0, 0.6, 0.3)
pitch = math.atan2(eye[1] - target[1], eye[2] - target[2])
nodes.append({"name": "camera", "camera": 0, "translation": list(eye),
              "rotation": [-math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]})
gltf = {
    "asset": {"version": "2.0", "generator": "nusselt tools/make_materials_scene.py"},
    "extensionsUsed": ["NUSSELT_brdf", "KHR_materials_emissive_strength", "KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"name": "fill", "type": "directional", "intensity": 0.6,
                                                       "color": [0.8, 0.85, 1.0]}]}},
    "scene": 0, "scenes": [{"nodes": list(range(len(nodes) + 1))}],
    "nodes": nodes + [{"name": "fill", "rotation": [-0.3535534, 0.3535534, 0.1464466, 0.8535534],
                       "extensions": {"KHR_lights_punctual": {"light": 0}}}],
    "meshes": meshes, "materials": materials,
    "cameras": [{"name": "camera", "type": "perspective", "perspective": {"yfov": 0.75, "aspectRatio": 1.25, "znear": 0.1}}],
    "accessors": accessors, "bufferViews": views,
    "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
}
out = Path(__file__).resolve().parent.parent / "scenes" / "materials" / "materials.gltf"
out.parent.mkdir(parents=True, exist_ok=True)
out.write_text(json.dumps(gltf) + "\n")
print("wrote", out, "(%d models)" % len(MODELS))
