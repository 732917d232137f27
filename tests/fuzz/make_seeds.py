#!/usr/bin/env python3
"""Writes the generated glTF/GLB seeds of tests/fuzz/corpus/gltf (the others are copies of
tests/data/gltf, scenes/tests and scenes/cornell-box.glb, or written by tools/make_test_assets.sh). Small files that between them reach
every branch of the loader: embedded and GLB buffers, strips and fans, index types, normals,
NUSSELT_brdf (single model and components), lights, cameras, emissive strength, hierarchies."""
import base64, json, os, struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "gltf")


def floats(*v):
    return struct.pack("<%df" % len(v), *v)


def scene(buf, accessors, views, prims, extra=None, glb=False):
    g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
         "nodes": [{"mesh": 0}], "meshes": [{"primitives": prims}],
         "accessors": accessors, "bufferViews": views,
         "buffers": [{"byteLength": len(buf)}]}
    if not glb:
        g["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(buf).decode()
    for k, v in (extra or {}).items():
        g[k] = v
    if not glb:
        return json.dumps(g, separators=(",", ":")).encode()
    js = json.dumps(g, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bb = buf + b"\0" * (-len(buf) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bb), 0x004E4942) + bb
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


quad = floats(0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
normals = floats(*([0, 0, 1] * 4))
pos = {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}
nrm = {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}
views = [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48}]
seeds = {}

idx16 = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
b = quad + normals + idx16
v = views + [{"buffer": 0, "byteOffset": 96, "byteLength": 12, "target": 34963}]
a = [pos, nrm, {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]
prim = [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]
mats = {"materials": [{"name": "ward", "extensions": {"NUSSELT_brdf": {"model": "ward", "params": {
    "kd": 0.2, "ks": 0.5, "ax": 0.1, "ay": 0.3, "normalization": "duer"}}}}],
        "extensionsUsed": ["NUSSELT_brdf"]}
seeds["quad_indexed_brdf.gltf"] = scene(b, a, v, prim, mats)
seeds["quad_indexed_brdf.glb"] = scene(b, a, v, prim, mats, glb=True)

for mode, name in ((5, "strip"), (6, "fan"), (4, "list")):
    seeds["quad_%s.gltf" % name] = scene(quad + normals, [pos, nrm], views,
                                         [{"attributes": {"POSITION": 0, "NORMAL": 1}, "mode": mode}])

idx8 = bytes([0, 1, 2, 0, 2, 3])
idx32 = struct.pack("<6I", 0, 1, 2, 0, 2, 3)
for ct, data, name in ((5121, idx8, "u8"), (5125, idx32, "u32")):
    b = quad + data
    seeds["quad_indices_%s.glb" % name] = scene(
        b, [pos, {"bufferView": 1, "componentType": ct, "count": 6, "type": "SCALAR"}],
        [views[0], {"buffer": 0, "byteOffset": 48, "byteLength": len(data)}],
        [{"attributes": {"POSITION": 0}, "indices": 1}], glb=True)

# interleaved position + normal, byteStride 24
inter = b"".join(floats(*quad_p) + floats(0, 0, 1) for quad_p in
                 ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)))
seeds["quad_interleaved.gltf"] = scene(
    inter, [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"}],
    [{"buffer": 0, "byteLength": 96, "byteStride": 24}],
    [{"attributes": {"POSITION": 0, "NORMAL": 1}, "mode": 6}])

full = {
    "nodes": [{"mesh": 0, "children": [1, 2, 3], "scale": [2, 2, -2], "rotation": [0, 0.3826834, 0, 0.9238795]},
              {"camera": 0, "translation": [0, 0.5, 3], "name": "cam"},
              {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 1, 0]},
              {"extensions": {"KHR_lights_punctual": {"light": 1}},
               "matrix": [1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 2, 0, 1]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.01, "aspectRatio": 1.5}},
                {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0, "zfar": 10}}],
    "materials": [{"emissiveFactor": [1, 0.5, 0.25], "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1]},
                   "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 10}}}],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 1, 1], "intensity": 5},
        {"type": "spot", "intensity": 3, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
        {"type": "directional", "intensity": 1}]}},
    "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
}
seeds["hierarchy_lights_camera.gltf"] = scene(quad + normals, [pos, nrm], views,
                                              [{"attributes": {"POSITION": 0, "NORMAL": 1}, "mode": 6, "material": 0}],
                                              full)
seeds["hierarchy_lights_camera.glb"] = scene(quad + normals, [pos, nrm], views,
                                             [{"attributes": {"POSITION": 0, "NORMAL": 1}, "mode": 6, "material": 0}],
                                             full, glb=True)
nan = floats(0, 0, 0, float("nan"), 0, 0, 1, 1, 0, 0, 1, float("inf"))
seeds["nonfinite_vertices.gltf"] = scene(nan + normals, [pos, nrm], views,
                                         [{"attributes": {"POSITION": 0, "NORMAL": 1}, "mode": 6}])

combined = {"materials": [{"name": "glaze", "extensions": {"NUSSELT_brdf": {"components": [
    {"model": "lambert", "weight": 0.6, "params": {"rho": [0.5, 0.4, 0.3]}},
    {"model": "phong", "weight": 1.0, "params": {"kd": 0, "ks": 0.3, "n": 50}},
    {"model": "mirror", "weight": 0.2, "params": {"eta": 0.96, "k": 6.69}}]}}}],
            "extensionsUsed": ["NUSSELT_brdf"]}
seeds["quad_combined_brdf.gltf"] = scene(quad + normals + idx16, a, v, prim, combined)

# Textures (issue 18): data-URI PNG and JPEG images (the committed test images), a sampler, a
# texture transform, TEXCOORD_0/1, TANGENT, alpha, transmission, ior and volume.
IMAGES = os.path.join(os.path.dirname(OUT), "..", "..", "data", "images")
def image_uri(name, mime):
    with open(os.path.join(IMAGES, name), "rb") as f:
        return "data:%s;base64,%s" % (mime, base64.b64encode(f.read()).decode())
uv = floats(0, 1, 1, 1, 1, 0, 0, 0)
tangents = floats(*([1, 0, 0, 1] * 4))
tex_views = views + [{"buffer": 0, "byteOffset": 96, "byteLength": 32}, {"buffer": 0, "byteOffset": 128, "byteLength": 64},
                     {"buffer": 0, "byteOffset": 192, "byteLength": 12}]
tex_acc = [pos, nrm, {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
           {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"},
           {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}]
tex_prim = [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TEXCOORD_1": 2, "TANGENT": 3}, "indices": 4,
             "material": 0}]
textured = {
    "images": [{"uri": image_uri("rgba8.png", "image/png")}, {"uri": image_uri("grey.jpg", "image/jpeg")}],
    "samplers": [{"magFilter": 9728, "minFilter": 9986, "wrapS": 33648, "wrapT": 33071}],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
    "materials": [{"alphaMode": "BLEND", "doubleSided": True,
                   "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                       "offset": [0.5, 0], "rotation": 0.3, "scale": [2, 2], "texCoord": 1}}},
                                            "metallicRoughnessTexture": {"index": 1}},
                   "normalTexture": {"index": 0, "scale": 0.8}, "emissiveTexture": {"index": 1}, "emissiveFactor": [1, 1, 1],
                   "occlusionTexture": {"index": 1},
                   "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5, "transmissionTexture": {"index": 1}},
                                  "KHR_materials_ior": {"ior": 1.4},
                                  "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationDistance": 2,
                                                           "attenuationColor": [0.5, 0.6, 0.7]}}}],
    "extensionsUsed": ["KHR_texture_transform", "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
}
seeds["quad_textured.gltf"] = scene(quad + normals + uv + tangents + idx16, tex_acc, tex_views, tex_prim, textured)
no_tangent = [dict(tex_prim[0], attributes={"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2})]
seeds["quad_normal_map_generated_tangents.glb"] = scene(quad + normals + uv + tangents + idx16, tex_acc, tex_views,
                                                        no_tangent, textured, glb=True)

for name, data in seeds.items():
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(data)
print("wrote %d seeds to %s" % (len(seeds), OUT))
