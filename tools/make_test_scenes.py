#!/usr/bin/env python3
"""Generates the renderer's test scenes in scenes/tests/ (glTF with embedded base64 buffers).

  furnace.gltf   closed unit sphere seen from inside: lambert rho 0.5, emission 1 everywhere;
                 every pixel converges to Le / (1 - rho) = 2. The pole triangles are zero-area
                 on purpose (the loader must drop them: 64 of 1024).
  mis.gltf       a floor under a large dim and a small bright emissive quad (MIS test).
  punctual.gltf  a floor lit by one point and one spot light (KHR_lights_punctual).
  environment.gltf  no light at all (the environment tests add one): a Lambert sphere (rho 0.5) at
                 x = -1.2 and a mirror sphere (silver-like complex index) at x = +1.2, radius 1,
                 seen from +z by a camera looking along -z (the map's centre).
  env_bench.gltf     the environment benchmark's scene: a Lambert floor, a Lambert sphere and a
                 glossy metal sphere (glTF metallic-roughness, roughness 0.3); no light.
  env_bench_area.gltf  the same lit by an emissive quad above it (the speed comparison).
  combined.gltf  combined materials (NUSSELT_brdf components) in a small coloured box under an
                 area light: lambert + phong + mirror, lambert + dielectric, a saturated lambert
                 + a white phong; for renders that exercise every combined-material code path.
  combined_indirect.gltf  the same box with its light lowered to y = 1.7 and turned to face the
                 ceiling (lit only indirectly, as scenes/cornell/cornell-indirect.glb): where path
                 guiding pays, on combined materials (tools/bench_guiding.sh).
  textures.gltf  glTF textures as the renderer applies them (docs/scenes.md, "Textures"): a
                 gltf_pbr floor with a baseColor checker (NEAREST, REPEAT, KHR_texture_transform
                 scale 3) and a metallicRoughness gradient (LINEAR, CLAMP_TO_EDGE: roughness
                 along x, metallic along z), a back wall with a baseColor texture on TEXCOORD_1
                 (LINEAR, MIRRORED_REPEAT) and a lamp with an emissive stripe texture (sRGB).
                 The PNGs are generated here (zlib) and embedded as data URIs.
  glass_slab.gltf  a slab of glass (KHR_materials_transmission 1, KHR_materials_ior 1.5, metallic 0,
                 KHR_materials_volume thickness 0.2: a refracting volume, not thin-walled)
                 between z = 0.2 and 0.4 (its top and bottom faces, outward normals) over an
                 emitter of radiance 1 at z = 0 facing +z; camera above, looking down. Seen
                 through the slab at normal incidence the emitter converges to (1 - R) / (1 + R)
                 with R = 0.04 (both faces and every internal reflection).
  glass_slab_tinted.gltf  glass_slab.gltf's slab with KHR_materials_volume attenuationColor
                 (0.8, 0.5, 0.2) at attenuationDistance 0.2 (= its thickness): at normal incidence
                 the emitter converges to (1 - R)^2 c / (1 - R^2 c^2) per channel.
  glass_slab_base_color.gltf  glass_slab.gltf's slab with baseColorFactor (0.8, 0.5, 0.2), which
                 tints the light it transmits at each of its two faces (KHR_materials_transmission's
                 tinting; KHR_materials_volume: a coloured foil on the boundary): at normal
                 incidence the emitter converges to c^2 (1 - R) / (1 + R) per channel.
  thin_rough_sheet.gltf  a thin-walled rough sheet (KHR_materials_transmission 1, ior 1.5,
                 roughness 0.7, metallic 0, baseColorFactor (0.8, 0.5, 0.2), no KHR_materials_volume:
                 the loader's rough_thin_dielectric, alpha 0.49) at z = 0.3, 6 x 6, facing +z, over
                 an emitter of radiance 1 at z = 0, 2 x 2, facing +z; camera above, looking down.
                 The lamp is seen through the sheet blurred, tinted by the base colour.
  guiding_gap.gltf  two rooms (4 x 2 x 2, Lambert rho 0.7) divided by a wall at x = 0 with a
                 0.3 x 0.3 opening at its centre; the area light is on the ceiling of the left room,
                 the camera in the right one: the right room sees light only through the opening
                 (path guiding's benchmark, docs/guiding.md).

Emissive surfaces are one-sided: they emit on the side of their geometric normal
(v1 - v0) x (v2 - v0), so every triangle here is wound to face where it should emit or be seen.
Standard library only; run from anywhere: python3 tools/make_test_scenes.py
"""
import base64
import json
import math
import os
import struct
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "scenes", "tests")


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def normalize(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def look_at_quaternion(eye, target, up=(0.0, 1.0, 0.0)):
    """Rotation (x, y, z, w) turning a glTF camera (looking down -z, +y up) towards target."""
    f = normalize(sub(target, eye))
    z = [-c for c in f]
    x = normalize(cross(list(up), z))
    y = cross(z, x)
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]  # columns x, y, z
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, qx, qy, qz = 0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        w, qx, qy, qz = (m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        w, qx, qy, qz = (m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        w, qx, qy, qz = (m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s
    return [qx, qy, qz, w]


def png_rgba(width, height, texel):
    """An 8-bit RGBA PNG (colour type 6, no interlace) of texel(x, y) -> (r, g, b, a), row 0 on top."""
    def chunk(kind, payload):
        return (struct.pack(">I", len(payload)) + kind + payload +
                struct.pack(">I", zlib.crc32(kind + payload) & 0xffffffff))
    raw = b"".join(b"\0" + bytes(c for x in range(width) for c in texel(x, y)) for y in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


class Builder:
    """Accumulates meshes into one buffer and emits a glTF document."""

    def __init__(self):
        self.data = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "nusselt tools/make_test_scenes.py"},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
            "extensionsUsed": [],
        }

    def use(self, ext):
        if ext not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append(ext)

    def _view(self, payload, target):
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        self.data += payload
        self.doc["bufferViews"].append(
            {"buffer": 0, "byteOffset": offset, "byteLength": len(payload), "target": target})
        return len(self.doc["bufferViews"]) - 1

    def _vec3_accessor(self, values, with_bounds):
        payload = b"".join(struct.pack("<3f", *v) for v in values)
        acc = {"bufferView": self._view(payload, 34962), "componentType": 5126, "count": len(values),
               "type": "VEC3"}
        if with_bounds:
            # min/max of the float32 values, as the spec requires for POSITION
            f = [struct.unpack("<3f", struct.pack("<3f", *v)) for v in values]
            acc["min"] = [min(p[i] for p in f) for i in range(3)]
            acc["max"] = [max(p[i] for p in f) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, rho, emission=(0.0, 0.0, 0.0), strength=None):
        self.use("NUSSELT_brdf")
        mat = {"name": name,
               "pbrMetallicRoughness": {"baseColorFactor": [rho, rho, rho, 1.0], "metallicFactor": 0.0},
               "extensions": {"NUSSELT_brdf": {"model": "lambert", "params": {"rho": [rho, rho, rho]}}}}
        if any(emission):
            mat["emissiveFactor"] = list(emission)
        if strength is not None:
            self.use("KHR_materials_emissive_strength")
            mat["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def combined_material(self, name, components):
        self.use("NUSSELT_brdf")
        mat = {"name": name, "extensions": {"NUSSELT_brdf": {"components": components}}}
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def _vec2_accessor(self, values):
        payload = b"".join(struct.pack("<2f", *v) for v in values)
        self.doc["accessors"].append({"bufferView": self._view(payload, 34962), "componentType": 5126,
                                      "count": len(values), "type": "VEC2"})
        return len(self.doc["accessors"]) - 1

    def texture(self, png, mag, wrap_s, wrap_t):
        """A texture of a PNG (bytes, embedded as a data URI) with its own sampler; returns its index."""
        self.doc.setdefault("images", []).append(
            {"uri": "data:image/png;base64," + base64.b64encode(png).decode("ascii")})
        self.doc.setdefault("samplers", []).append({"magFilter": mag, "minFilter": mag, "wrapS": wrap_s,
                                                    "wrapT": wrap_t})
        self.doc.setdefault("textures", []).append({"source": len(self.doc["images"]) - 1,
                                                    "sampler": len(self.doc["samplers"]) - 1})
        return len(self.doc["textures"]) - 1

    def pbr_material(self, name, pbr, **extra):
        """A glTF metallic-roughness material (no NUSSELT_brdf: the renderer's gltf_pbr)."""
        self.doc["materials"].append(dict({"name": name, "pbrMetallicRoughness": pbr}, **extra))
        return len(self.doc["materials"]) - 1

    def mesh(self, name, positions, normals, indices, material, texcoords=()):
        pos = self._vec3_accessor(positions, True)
        nrm = self._vec3_accessor(normals, False)
        attributes = {"POSITION": pos, "NORMAL": nrm}
        for k, uv in enumerate(texcoords):
            attributes["TEXCOORD_%d" % k] = self._vec2_accessor(uv)
        payload = b"".join(struct.pack("<I", i) for i in indices)
        while len(payload) % 4:
            payload += b"\0"
        self.doc["accessors"].append({"bufferView": self._view(payload, 34963), "componentType": 5125,
                                      "count": len(indices), "type": "SCALAR"})
        ind = len(self.doc["accessors"]) - 1
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": attributes, "indices": ind, "material": material, "mode": 4}]})
        self.node({"name": name, "mesh": len(self.doc["meshes"]) - 1})

    def quad(self, name, corners, material, texcoords=()):
        """corners in counter-clockwise order seen from the front (the emitting side); texcoords:
        per set, the four corners' (u, v)."""
        n = normalize(cross(sub(corners[1], corners[0]), sub(corners[2], corners[0])))
        self.mesh(name, corners, [n] * 4, [0, 1, 2, 0, 2, 3], material, texcoords)

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def camera(self, name, eye, target, yfov, aspect=None):
        persp = {"yfov": yfov, "znear": 0.01}
        if aspect:
            persp["aspectRatio"] = aspect
        self.doc.setdefault("cameras", []).append({"name": name, "type": "perspective", "perspective": persp})
        node = {"name": name, "camera": len(self.doc["cameras"]) - 1, "translation": list(eye)}
        if target is not None:
            node["rotation"] = look_at_quaternion(eye, target)
        self.node(node)

    def light(self, name, light, translation, rotation=None):
        self.use("KHR_lights_punctual")
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
        light = dict(light, name=name)
        ext["lights"].append(light)
        node = {"name": name, "translation": list(translation),
                "extensions": {"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}}}
        if rotation:
            node["rotation"] = rotation
        self.node(node)

    def write(self, filename):
        while len(self.data) % 4:
            self.data.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.data),
                                "uri": "data:application/octet-stream;base64," +
                                       base64.b64encode(bytes(self.data)).decode("ascii")}]
        if not self.doc["extensionsUsed"]:
            del self.doc["extensionsUsed"]
        os.makedirs(OUT, exist_ok=True)
        path = os.path.join(OUT, filename)
        with open(path, "w") as f:
            json.dump(self.doc, f, indent=1)
            f.write("\n")
        print("wrote", os.path.relpath(path, ROOT))


def furnace():
    b = Builder()
    rows, cols = 16, 32
    positions, normals = [], []
    for i in range(rows + 1):
        theta = math.pi * i / rows
        for j in range(cols + 1):
            phi = 2 * math.pi * j / cols
            if i == 0 or i == rows:
                # exact poles: the pole triangles are exactly zero-area (the loader drops them)
                p = [0.0, 1.0 if i == 0 else -1.0, 0.0]
            else:
                p = [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
            positions.append(p)
            normals.append([-c for c in p])  # inward: the camera is inside
    indices = []
    for i in range(rows):
        for j in range(cols):
            a, c = i * (cols + 1) + j, (i + 1) * (cols + 1) + j
            for tri in ((a, a + 1, c), (a + 1, c + 1, c)):
                p0, p1, p2 = (positions[k] for k in tri)
                g = cross(sub(p1, p0), sub(p2, p0))
                centroid = [(p0[k] + p1[k] + p2[k]) / 3 for k in range(3)]
                if dot(g, centroid) > 0:  # outward: reverse to face the centre
                    tri = (tri[0], tri[2], tri[1])
                indices.extend(tri)
    # check: every non-degenerate triangle faces inward
    for t in range(0, len(indices), 3):
        p0, p1, p2 = (positions[k] for k in indices[t:t + 3])
        g = cross(sub(p1, p0), sub(p2, p0))
        assert dot(g, g) == 0 or dot(g, [(p0[k] + p1[k] + p2[k]) for k in range(3)]) < 0
    mat = b.material("furnace", 0.5, emission=(1.0, 1.0, 1.0))
    b.mesh("sphere", positions, normals, indices, mat)
    b.camera("centre", (0.0, 0.0, 0.0), None, 1.0)
    b.write("furnace.gltf")


def uv_sphere(centre, radius, rows=24, cols=48):
    """A closed UV sphere (outward normals and winding) as positions, normals, indices."""
    positions, normals = [], []
    for i in range(rows + 1):
        theta = math.pi * i / rows
        for j in range(cols + 1):
            phi = 2 * math.pi * j / cols
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
            positions.append([centre[k] + radius * n[k] for k in range(3)])
            normals.append(n)
    indices = []
    for i in range(rows):
        for j in range(cols):
            a, c = i * (cols + 1) + j, (i + 1) * (cols + 1) + j
            for tri in ((a, a + 1, c), (a + 1, c + 1, c)):
                p0, p1, p2 = (positions[k] for k in tri)
                g = cross(sub(p1, p0), sub(p2, p0))
                if dot(g, g) < 1e-20:
                    continue  # pole triangles: zero area
                mid = [(p0[k] + p1[k] + p2[k]) / 3 - centre[k] for k in range(3)]
                if dot(g, mid) < 0:
                    tri = (tri[0], tri[2], tri[1])
                indices.extend(tri)
    return positions, normals, indices


def environment():
    b = Builder()
    diffuse = b.material("diffuse", 0.5)
    b.use("NUSSELT_brdf")
    b.doc["materials"].append({"name": "mirror", "extensions": {"NUSSELT_brdf": {
        "model": "mirror", "params": {"eta": [0.155, 0.117, 0.138], "k": [4.83, 3.12, 2.15]}}}})
    mirror = len(b.doc["materials"]) - 1
    b.mesh("diffuse_sphere", *uv_sphere((-1.2, 0.0, 0.0), 1.0), diffuse)
    b.mesh("mirror_sphere", *uv_sphere((1.2, 0.0, 0.0), 1.0), mirror)
    b.camera("camera", (0.0, 0.0, 6.0), None, 0.7, 2.0)
    b.write("environment.gltf")


def env_bench(area):
    b = Builder()
    floor = b.material("floor", 0.6)
    diffuse = b.material("diffuse", 0.5)
    b.doc["materials"].append({"name": "glossy_metal", "pbrMetallicRoughness": {
        "baseColorFactor": [0.95, 0.8, 0.6, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.3}})
    glossy = len(b.doc["materials"]) - 1
    b.quad("floor", [[-4, 0, -4], [-4, 0, 4], [4, 0, 4], [4, 0, -4]], floor)
    b.mesh("diffuse_sphere", *uv_sphere((-1.1, 1.0, 0.0), 1.0), diffuse)
    b.mesh("glossy_sphere", *uv_sphere((1.1, 1.0, 0.0), 1.0), glossy)
    if area:
        light = b.material("light", 0.0, emission=(1.0, 1.0, 1.0), strength=20.0)
        b.quad("light", [[-0.5, 4, -0.5], [0.5, 4, -0.5], [0.5, 4, 0.5], [-0.5, 4, 0.5]], light)
    b.camera("camera", (0.0, 2.2, 6.5), (0.0, 0.8, 0.0), 0.7, 1.5)
    b.write("env_bench_area.gltf" if area else "env_bench.gltf")


def mis():
    b = Builder()
    floor = b.material("floor", 0.5)
    large = b.material("large_dim", 0.0, emission=(0.5, 0.5, 0.5))
    small = b.material("small_bright", 0.0, emission=(1.0, 1.0, 1.0), strength=50.0)
    # floor y = 0 facing +y (counter-clockwise seen from above)
    b.quad("floor", [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]], floor)
    # emitters at y = 1.5 facing down (-y): counter-clockwise seen from below
    b.quad("large_dim", [[-1.5, 1.5, -0.6], [-0.25, 1.5, -0.6], [-0.25, 1.5, 0.4], [-1.5, 1.5, 0.4]], large)
    b.quad("small_bright", [[0.7, 1.5, -0.15], [0.8, 1.5, -0.15], [0.8, 1.5, -0.05], [0.7, 1.5, -0.05]], small)
    b.camera("camera", (0.0, 1.0, 4.0), (0.0, 0.2, 0.0), 0.8, 1.0)
    b.write("mis.gltf")


def punctual():
    b = Builder()
    floor = b.material("floor", 0.5)
    b.quad("floor", [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]], floor)
    b.light("point", {"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 2.0}, (-1.0, 1.0, 0.0))
    s = math.sqrt(0.5)  # -90 degrees about x: the node's -z points down
    b.light("spot", {"type": "spot", "color": [1.0, 0.9, 0.8], "intensity": 5.0,
                     "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}}, (1.0, 1.5, 0.0), [-s, 0.0, 0.0, s])
    b.camera("camera", (0.0, 3.0, 5.0), (0.0, 0.0, 0.0), 0.7, 1.0)
    b.write("punctual.gltf")


def combined(indirect=False):
    b = Builder()
    tile = b.combined_material("tile", [
        {"model": "lambert", "weight": 0.6, "params": {"rho": [0.5, 0.4, 0.3]}},
        {"model": "phong", "params": {"kd": 0, "ks": 0.3, "n": 50}},
        {"model": "mirror", "weight": 0.2, "params": {"eta": 0.96, "k": 6.69}}])
    glazed = b.combined_material("glazed", [
        {"model": "lambert", "weight": 0.5, "params": {"rho": [0.2, 0.6, 0.2]}},
        {"model": "dielectric", "weight": 0.5, "params": {"eta": 1.5}}])
    red = b.combined_material("red_gloss", [
        {"model": "lambert", "params": {"rho": [0.57, 0.043, 0.044]}},
        {"model": "phong", "params": {"kd": 0, "ks": 0.2, "n": 200}}])
    white = b.material("white", 0.7)
    light = b.material("light", 0.0, emission=(1.0, 1.0, 1.0), strength=10.0)
    b.quad("floor", [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]], tile)
    b.quad("back", [[-1, 0, -1], [1, 0, -1], [1, 2, -1], [-1, 2, -1]], glazed)
    b.quad("left", [[-1, 0, 1], [-1, 0, -1], [-1, 2, -1], [-1, 2, 1]], red)
    b.quad("right", [[1, 0, -1], [1, 0, 1], [1, 2, 1], [1, 2, -1]], white)
    b.quad("ceiling", [[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]], white)
    if indirect:  # facing +y (counter-clockwise seen from above, as the floor)
        b.quad("light", [[-0.3, 1.7, -0.3], [-0.3, 1.7, 0.3], [0.3, 1.7, 0.3], [0.3, 1.7, -0.3]], light)
    else:
        b.quad("light", [[-0.3, 1.99, -0.3], [0.3, 1.99, -0.3], [0.3, 1.99, 0.3], [-0.3, 1.99, 0.3]], light)
    b.camera("camera", (0.0, 1.0, 3.4), (0.0, 1.0, 0.0), 0.8, 1.0)
    b.write("combined_indirect.gltf" if indirect else "combined.gltf")


def textures():
    b = Builder()
    NEAREST, LINEAR, REPEAT, CLAMP, MIRROR = 9728, 9729, 10497, 33071, 33648
    checker = b.texture(png_rgba(8, 8, lambda x, y: (230, 220, 200, 255) if (x + y) % 2 == 0 else (40, 70, 140, 255)),
                        NEAREST, REPEAT, REPEAT)
    # G = roughness (0.1 at the left to 1 at the right), B = metallic (0 at the back, 1 at the front)
    gradient = b.texture(png_rgba(8, 8, lambda x, y: (0, 25 + 230 * x // 7, 255 * y // 7, 255)), LINEAR, CLAMP, CLAMP)
    stripes = b.texture(png_rgba(4, 4, lambda x, y: (255, 230, 180, 255) if x % 2 == 0 else (60, 90, 255, 255)),
                        NEAREST, CLAMP, CLAMP)
    wall = b.texture(png_rgba(4, 4, lambda x, y: (40 + 60 * x, 120, 40 + 60 * y, 255)), LINEAR, MIRROR, MIRROR)
    b.use("KHR_texture_transform")
    floor = b.pbr_material("floor", {
        "baseColorTexture": {"index": checker, "extensions": {"KHR_texture_transform": {"scale": [3, 3]}}},
        "metallicRoughnessTexture": {"index": gradient}, "metallicFactor": 1.0, "roughnessFactor": 1.0})
    back = b.pbr_material("back", {"baseColorTexture": {"index": wall, "texCoord": 1}, "metallicFactor": 0.0})
    lamp = b.pbr_material("lamp", {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
                          emissiveFactor=[1.0, 1.0, 1.0], emissiveTexture={"index": stripes})
    b.doc["materials"][lamp]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 6.0}}
    b.use("KHR_materials_emissive_strength")
    unit = [[0, 1], [1, 1], [1, 0], [0, 0]]
    b.quad("floor", [[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]], floor, [unit])
    # TEXCOORD_0 is a decoy (all zero): the wall's texture reads TEXCOORD_1, which spans [-1, 2] (mirrored)
    b.quad("back", [[-2, 0, -2], [2, 0, -2], [2, 2, -2], [-2, 2, -2]], back,
           [[[0, 0]] * 4, [[-1, 2], [2, 2], [2, -1], [-1, -1]]])
    # the lamp at y = 1.6 facing down: counter-clockwise seen from below
    b.quad("lamp", [[-0.6, 1.6, -0.6], [0.6, 1.6, -0.6], [0.6, 1.6, 0.6], [-0.6, 1.6, 0.6]], lamp, [unit])
    b.camera("camera", (0.0, 0.9, 4.2), (0.0, 0.7, 0.0), 0.8, 1.0)
    b.write("textures.gltf")


def slab_scene(material, volume, filename, base_color=None):
    """A lamp at z = 0 seen through a slab of `material` between z = 0.2 and 0.4 (its
    KHR_materials_volume: `volume`; its baseColorFactor `base_color`, default white)."""
    b = Builder()
    b.use("KHR_materials_transmission")
    b.use("KHR_materials_ior")
    b.use("KHR_materials_volume")
    pbr = {"metallicFactor": 0.0, "roughnessFactor": 0.0}
    if base_color is not None:
        pbr["baseColorFactor"] = list(base_color) + [1.0]
    glass = b.pbr_material(material, pbr,
                           extensions={"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                       "KHR_materials_ior": {"ior": 1.5},
                                       "KHR_materials_volume": volume})
    lamp = b.material("lamp", 0.0, emission=(1.0, 1.0, 1.0))
    b.quad("lamp", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], lamp)
    b.quad("top", [[-1, -1, 0.4], [1, -1, 0.4], [1, 1, 0.4], [-1, 1, 0.4]], glass)
    b.quad("bottom", [[-1, -1, 0.2], [-1, 1, 0.2], [1, 1, 0.2], [1, -1, 0.2]], glass)
    b.camera("camera", (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), 0.3, 1.0)
    b.write(filename)


def glass_slab():
    # The volume's thickness makes the slab refract (without it glTF's transmission is thin-walled).
    slab_scene("glass", {"thicknessFactor": 0.2}, "glass_slab.gltf")


def glass_slab_tinted():
    # attenuationDistance = the slab's thickness: at normal incidence one crossing transmits
    # attenuationColor.
    slab_scene("tinted", {"thicknessFactor": 0.2, "attenuationDistance": 0.2,
                          "attenuationColor": [0.8, 0.5, 0.2]}, "glass_slab_tinted.gltf")


def glass_slab_base_color():
    # The base colour tints each crossing of the boundary (both faces).
    slab_scene("coloured", {"thicknessFactor": 0.2}, "glass_slab_base_color.gltf", base_color=(0.8, 0.5, 0.2))


def thin_rough_sheet():
    b = Builder()
    b.use("KHR_materials_transmission")
    b.use("KHR_materials_ior")
    sheet = b.pbr_material("frosted pane", {"metallicFactor": 0.0, "roughnessFactor": 0.7,
                                            "baseColorFactor": [0.8, 0.5, 0.2, 1.0]},
                           extensions={"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                       "KHR_materials_ior": {"ior": 1.5}})
    lamp = b.material("lamp", 0.0, emission=(1.0, 1.0, 1.0))
    b.quad("lamp", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], lamp)
    b.quad("sheet", [[-3, -3, 0.3], [3, -3, 0.3], [3, 3, 0.3], [-3, 3, 0.3]], sheet)
    b.camera("camera", (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), 0.3, 1.0)
    b.write("thin_rough_sheet.gltf")


def guiding_gap():
    b = Builder()
    white = b.material("white", 0.7)
    light = b.material("light", 0.0, emission=(1.0, 1.0, 1.0), strength=30.0)
    b.quad("floor", [[-2, 0, -1], [-2, 0, 1], [2, 0, 1], [2, 0, -1]], white)
    b.quad("ceiling", [[-2, 2, -1], [2, 2, -1], [2, 2, 1], [-2, 2, 1]], white)
    b.quad("back", [[-2, 0, -1], [2, 0, -1], [2, 2, -1], [-2, 2, -1]], white)
    b.quad("front", [[-2, 0, 1], [-2, 2, 1], [2, 2, 1], [2, 0, 1]], white)
    b.quad("left", [[-2, 0, 1], [-2, 0, -1], [-2, 2, -1], [-2, 2, 1]], white)
    b.quad("right", [[2, 0, -1], [2, 0, 1], [2, 2, 1], [2, 2, -1]], white)
    # The dividing wall at x = 0 around its opening y in [0.85, 1.15], z in [-0.15, 0.15].
    b.quad("wall_below", [[0, 0, -1], [0, 0, 1], [0, 0.85, 1], [0, 0.85, -1]], white)
    b.quad("wall_above", [[0, 1.15, -1], [0, 1.15, 1], [0, 2, 1], [0, 2, -1]], white)
    b.quad("wall_back", [[0, 0.85, -1], [0, 0.85, -0.15], [0, 1.15, -0.15], [0, 1.15, -1]], white)
    b.quad("wall_front", [[0, 0.85, 0.15], [0, 0.85, 1], [0, 1.15, 1], [0, 1.15, 0.15]], white)
    b.quad("light", [[-1.5, 1.99, -0.4], [-0.5, 1.99, -0.4], [-0.5, 1.99, 0.4], [-1.5, 1.99, 0.4]], light)
    b.camera("camera", (1.95, 1.2, 0.9), (0.0, 0.7, -0.3), 1.2, 1.0)
    b.write("guiding_gap.gltf")


if __name__ == "__main__":
    furnace()
    mis()
    punctual()
    combined()
    combined(indirect=True)
    environment()
    env_bench(False)
    env_bench(True)
    textures()
    glass_slab()
    glass_slab_tinted()
    glass_slab_base_color()
    thin_rough_sheet()
    guiding_gap()
