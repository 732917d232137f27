#!/usr/bin/env python3
"""Writes the Cornell-box variants of scenes/cornell/ from the default scene scenes/cornell-box.glb
(its geometry, camera, albedos and light are kept; units are millimetres):

  cornell-glossy.glb    both blocks a rough metal: gltf_pbr with baseColor 1, metallic 1 and
                        roughness sqrt(0.1) (GGX alpha 0.1). Its Fresnel term is exactly 1
                        (Schlick with f0 = 1), so it differs from Mitsuba 3's `roughconductor`
                        (GGX, alpha 0.1, material "none", also F = 1) only in the masking term:
                        height-correlated Smith here, separable Smith in Mitsuba.
  cornell-glass.glb     the blocks removed; a smooth glass sphere (dielectric, eta 1.5) standing on
                        the floor under the light: an icosphere of 5120 flat triangles (4
                        subdivisions, no NORMAL: every renderer sees the same facets).
  cornell-indirect.glb  the light lowered by 50 mm and turned to face the ceiling: the room is lit
                        only by light that has bounced at least once.

Standard library only; run from anywhere: python3 tools/make_cornell_variants.py
"""
import json
import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE = os.path.join(ROOT, "scenes", "cornell-box.glb")
OUT = os.path.join(ROOT, "scenes", "cornell")

GLOSSY_ALPHA = 0.1           # GGX alpha of the glossy blocks (nusselt roughness = sqrt(alpha))
GLASS_ETA = 1.5
SPHERE_RADIUS = 100.0        # mm
SPHERE_SUBDIVISIONS = 4      # icosphere: 20 * 4^4 = 5120 triangles
INDIRECT_DROP = 50.0         # mm the light is lowered in cornell-indirect

COMPONENTS = {5126: ("f", 4), 5125: ("I", 4), 5123: ("H", 2), 5121: ("B", 1)}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def read_glb(path):
    """The JSON document and the binary chunk of a .glb file."""
    data = open(path, "rb").read()
    magic, version, _ = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67 or version != 2:
        raise SystemExit(f"{path}: not a glTF 2.0 binary file")
    jlen, _ = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + jlen])
    blen, _ = struct.unpack_from("<II", data, 20 + jlen)
    return doc, data[28 + jlen:28 + jlen + blen]


def read_accessor(doc, binary, index):
    """An accessor's values as a list of tuples (or of numbers for SCALAR)."""
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    fmt, size = COMPONENTS[acc["componentType"]]
    width = WIDTHS[acc["type"]]
    stride = view.get("byteStride", size * width)
    base = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    out = []
    for i in range(acc["count"]):
        v = struct.unpack_from("<" + fmt * width, binary, base + i * stride)
        out.append(v[0] if width == 1 else tuple(v))
    return out


def source_meshes(doc, binary):
    """name -> (positions, normals or None, triangles, material index) of the source's meshes."""
    meshes = {}
    for node in doc["nodes"]:
        if "mesh" not in node:
            continue
        if any(k in node for k in ("matrix", "translation", "rotation", "scale")):
            raise SystemExit(f"{SOURCE}: node {node['name']} has a transform; this script expects none")
        (prim,) = doc["meshes"][node["mesh"]]["primitives"]
        pos = read_accessor(doc, binary, prim["attributes"]["POSITION"])
        nrm = read_accessor(doc, binary, prim["attributes"]["NORMAL"]) if "NORMAL" in prim["attributes"] else None
        idx = read_accessor(doc, binary, prim["indices"])
        tris = [tuple(idx[i:i + 3]) for i in range(0, len(idx), 3)]
        meshes[node["name"]] = (pos, nrm, tris, prim["material"])
    return meshes


def icosphere(subdivisions):
    """Unit icosphere: vertices and counter-clockwise (outward-facing) triangles."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
            (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
            (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoints = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                m = [(verts[a][k] + verts[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                midpoints[key] = len(verts) - 1
            return midpoints[key]

        new = []
        for a, b, c in tris:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return verts, tris


def face_normal(p, tri):
    a, b, c = (p[i] for i in tri)
    e1 = [b[k] - a[k] for k in range(3)]
    e2 = [c[k] - a[k] for k in range(3)]
    return (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])


class GlbWriter:
    """Accumulates meshes into one binary chunk and writes a .glb."""

    def __init__(self, source_doc):
        self.bin = bytearray()
        self.doc = {
            "asset": dict(source_doc["asset"]),
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
            "cameras": source_doc["cameras"],
            "extensionsUsed": ["KHR_materials_emissive_strength", "NUSSELT_brdf"],
        }

    def _accessor(self, values, fmt, ctype, atype, target, minmax):
        while len(self.bin) % 4:
            self.bin.append(0)
        offset = len(self.bin)
        flat = [x for v in values for x in (v if isinstance(v, tuple) else (v,))]
        self.bin += struct.pack("<%d%s" % (len(flat), fmt), *flat)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(self.bin) - offset,
                                        "target": target})
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": ctype, "count": len(values),
               "type": atype}
        if minmax:
            w = WIDTHS[atype]
            # Bounds of the float32 values actually stored.
            stored = [struct.unpack("<f", struct.pack("<f", x))[0] for x in flat]
            acc["min"] = [min(stored[k::w]) for k in range(w)]
            acc["max"] = [max(stored[k::w]) for k in range(w)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, mat):
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, positions, normals, tris, material):
        attrs = {"POSITION": self._accessor(positions, "f", 5126, "VEC3", 34962, True)}
        if normals is not None:
            attrs["NORMAL"] = self._accessor(normals, "f", 5126, "VEC3", 34962, False)
        flat = [i for t in tris for i in t]
        big = max(flat) > 65535
        idx = self._accessor(flat, "I" if big else "H", 5125 if big else 5123, "SCALAR", 34963, False)
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": attrs, "indices": idx, "material": material, "mode": 4}]})
        self.doc["nodes"].append({"name": name, "mesh": len(self.doc["meshes"]) - 1})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path, description):
        self.doc["asset"]["generator"] = "nusselt tools/make_cornell_variants.py from scenes/cornell-box.glb"
        self.doc["asset"].setdefault("extras", {})["variant"] = description
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.bin)}]
        js = json.dumps(self.doc, separators=(",", ":")).encode()
        js += b" " * ((4 - len(js) % 4) % 4)
        total = 12 + 8 + len(js) + 8 + len(self.bin)
        with open(path, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, total))
            f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
            f.write(struct.pack("<II", len(self.bin), 0x004E4942) + bytes(self.bin))
        print(f"wrote {os.path.relpath(path, ROOT)} ({total} bytes)")


def build(doc, meshes, skip=(), new_materials=(), assign=None, extra_meshes=(), edit=None):
    """A variant: the source's materials plus `new_materials`; the source's meshes (minus `skip`,
    edited by `edit[name]`, given `assign[name]`, an index into new_materials); then `extra_meshes`
    (name, positions, normals, triangles, index into new_materials); then the camera."""
    w = GlbWriter(doc)
    for m in doc["materials"]:
        w.material(m)
    added = [w.material(m) for m in new_materials]
    for name, (pos, nrm, tris, mat) in meshes.items():
        if name in skip:
            continue
        if edit and name in edit:
            pos, nrm, tris = edit[name](pos, nrm, tris)
        if assign and name in assign:
            mat = added[assign[name]]
        w.mesh(name, pos, nrm, tris, mat)
    for name, pos, nrm, tris, material in extra_meshes:
        w.mesh(name, pos, nrm, tris, added[material])
    for node in doc["nodes"]:
        if "camera" in node:
            w.node(node)
    return w


def main():
    doc, binary = read_glb(SOURCE)
    meshes = source_meshes(doc, binary)
    os.makedirs(OUT, exist_ok=True)

    # Glossy: one shared rough-metal material on both blocks.
    rough = round(math.sqrt(GLOSSY_ALPHA), 6)
    metal = {
        "name": "glossy_metal",
        "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 1.0,
                                 "roughnessFactor": rough},
        "extensions": {"NUSSELT_brdf": {"model": "gltf_pbr",
                                        "params": {"baseColor": [1.0, 1.0, 1.0], "metallic": 1.0,
                                                   "roughness": rough}}},
        "extras": {"ggxAlpha": GLOSSY_ALPHA},
    }
    w = build(doc, meshes, new_materials=[metal], assign={"short_block": 0, "tall_block": 0})
    w.write(os.path.join(OUT, "cornell-glossy.glb"),
            f"both blocks rough metal: gltf_pbr baseColor 1, metallic 1, roughness {rough} (GGX alpha {GLOSSY_ALPHA})")

    # Glass: no blocks; an icosphere standing on the floor under the light's centre.
    light = meshes["light"][0]
    cx = (min(p[0] for p in light) + max(p[0] for p in light)) / 2
    cz = (min(p[2] for p in light) + max(p[2] for p in light)) / 2
    floor_y = max(p[1] for p in meshes["floor"][0])
    unit, tris = icosphere(SPHERE_SUBDIVISIONS)
    sphere = [(cx + SPHERE_RADIUS * v[0], floor_y + SPHERE_RADIUS * (1.0 + v[1]), cz + SPHERE_RADIUS * v[2])
              for v in unit]
    for t in tris:  # outward winding: the dielectric's outside is its front side
        n = face_normal(sphere, t)
        c = [sum(sphere[i][k] for i in t) / 3 - (cx, floor_y + SPHERE_RADIUS, cz)[k] for k in range(3)]
        assert sum(n[k] * c[k] for k in range(3)) > 0
    glass = {
        "name": "glass",
        "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
                                 "roughnessFactor": 0.0},
        "extensions": {"NUSSELT_brdf": {"model": "dielectric", "params": {"eta": GLASS_ETA}}},
    }
    w = build(doc, meshes, skip=("short_block", "tall_block"), new_materials=[glass],
              extra_meshes=[("glass_sphere", sphere, None, tris, 0)])
    w.write(os.path.join(OUT, "cornell-glass.glb"),
            f"glass sphere (dielectric eta {GLASS_ETA}, radius {SPHERE_RADIUS:g} mm, icosphere of "
            f"{len(tris)} flat triangles) on the floor under the light; no blocks")

    # Indirect: the light lowered and facing the ceiling (winding and normals reversed).
    def turn_up(pos, nrm, tris):
        pos = [(p[0], p[1] - INDIRECT_DROP, p[2]) for p in pos]
        nrm = [(-n[0], -n[1], -n[2]) for n in nrm] if nrm else None
        tris = [(a, c, b) for a, b, c in tris]
        for t in tris:
            assert face_normal(pos, t)[1] > 0
        return pos, nrm, tris

    w = build(doc, meshes, edit={"light": turn_up})
    w.write(os.path.join(OUT, "cornell-indirect.glb"),
            f"the light {INDIRECT_DROP:g} mm lower, facing the ceiling: the room is lit only indirectly")


if __name__ == "__main__":
    main()
