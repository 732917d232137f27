#!/usr/bin/env python3
"""Writes scenes/cornell-box.glb: the project's Cornell box asset with each material given the
NUSSELT_brdf extension "lambert" (rho = its base colour), because the Cornell box is meant to be
Lambertian and a glTF material without the extension renders with the glTF metallic-roughness
BRDF. The buffer, the geometry, the camera and the light are unchanged.
Usage: tools/make_cornell_scene.py SOURCE.glb   (the asset set's cornell-box.glb)"""
import json, struct, sys
from pathlib import Path

src = Path(sys.argv[1]).read_bytes()
magic, version, length = struct.unpack_from("<III", src, 0)
assert magic == 0x46546C67 and version == 2
jlen, jtype = struct.unpack_from("<II", src, 12)
gltf = json.loads(src[20:20 + jlen])
binary_chunk = src[20 + jlen:]
for m in gltf["materials"]:
    rgb = m.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])[:3]
    m.setdefault("extensions", {})["NUSSELT_brdf"] = {"model": "lambert", "params": {"rho": [min(max(c, 0.0), 1.0) for c in rgb]}}
used = gltf.setdefault("extensionsUsed", [])
if "NUSSELT_brdf" not in used:
    used.append("NUSSELT_brdf")
gltf["asset"]["generator"] = gltf["asset"].get("generator", "") + "; NUSSELT_brdf added by nusselt tools/make_cornell_scene.py"
js = json.dumps(gltf, separators=(",", ":")).encode()
js += b" " * ((4 - len(js) % 4) % 4)
out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + len(binary_chunk)) + struct.pack("<II", len(js), 0x4E4F534A) + js + binary_chunk
dst = Path(__file__).resolve().parent.parent / "scenes" / "cornell-box.glb"
dst.write_bytes(out)
print("wrote", dst)
