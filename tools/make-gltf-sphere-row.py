#!/usr/bin/env python3
# Writes a glTF of a row of spheres, one per material, on a floor, with a camera: the test scenes
# of glTF's material extensions and of the comparison with Blender's Cycles (docs/gltf.md).
# Usage: tools/make-gltf-sphere-row.py PRESET out.gltf   (PRESET: extensions, diffuse, metal, glass)
import base64, json, math, struct, sys

def sphere(rings=48, segments=96):
    pos, idx = [], []
    for i in range(rings + 1):
        t = math.pi * i / rings
        for j in range(segments + 1):
            p = 2 * math.pi * j / segments
            pos.append((math.sin(t) * math.cos(p), math.cos(t), -math.sin(t) * math.sin(p)))
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j; c = a + segments + 1
            if i != 0: idx += [a, c, a + 1]
            if i != rings - 1: idx += [a + 1, c, c + 1]
    return pos, idx

def material(base, metallic, roughness, **ext):
    m = {"pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0], "metallicFactor": metallic,
                                  "roughnessFactor": roughness}}
    if ext: m["extensions"] = ext
    return m

GLASS = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
         "KHR_materials_volume": {"thicknessFactor": 1.0}}
LAMBERT = {"KHR_materials_specular": {"specularFactor": 0.0}}
PRESETS = {
    "extensions": [
        material((0.9, 0.9, 0.6), 0, 0, KHR_materials_transmission={"transmissionFactor": 1.0}),
        material((1, 1, 1), 0, 0.05, **GLASS),
        material((1, 1, 1), 0, 0.05, KHR_materials_transmission={"transmissionFactor": 1.0},
                 KHR_materials_volume={"thicknessFactor": 1.0, "attenuationColor": [0.9, 0.5, 0.2],
                                       "attenuationDistance": 1.0}),
        material((0.8, 0.1, 0.1), 0, 0.7, KHR_materials_clearcoat={"clearcoatFactor": 1.0,
                                                                    "clearcoatRoughnessFactor": 0.05}),
        material((0.2, 0.2, 0.8), 0, 0.3, KHR_materials_specular={"specularFactor": 1.0,
                                                                   "specularColorFactor": [2, 1, 0.5]}),
    ],
    # Lambertian: KHR_materials_specular's factor 0 takes the specular layer away (f0 = f90 = 0).
    "diffuse": [material((0.8, 0.3, 0.2), 0, 1, **LAMBERT), material((0.2, 0.6, 0.3), 0, 1, **LAMBERT),
                material((0.9, 0.9, 0.9), 0, 1, **LAMBERT)],
    "metal": [material((0.95, 0.64, 0.54), 1, 0), material((0.9, 0.9, 0.9), 1, 0.3),
              material((1.0, 0.78, 0.34), 1, 0.6)],
    "glass": [material((1, 1, 1), 0, 0, **GLASS), material((1, 1, 1), 0, 0.2, **GLASS),
              material((0.9, 1.0, 0.9), 0, 0, **GLASS)],
}

preset, out = sys.argv[1], sys.argv[2]
materials = PRESETS[preset]
pos, idx = sphere()
floor = [(-30, -1, -30), (-30, -1, 30), (30, -1, 30), (30, -1, -30)]
blob = b"".join(struct.pack("<3f", *p) for p in pos)   # sphere positions = normals
blob_idx = struct.pack("<%dI" % len(idx), *idx)
blob_floor = b"".join(struct.pack("<3f", *p) for p in floor) + struct.pack("<6I", 0, 1, 2, 0, 2, 3)
bin_ = blob + blob_idx + blob_floor
views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(blob)},
         {"buffer": 0, "byteOffset": len(blob), "byteLength": len(blob_idx)},
         {"buffer": 0, "byteOffset": len(blob) + len(blob_idx), "byteLength": 48},
         {"buffer": 0, "byteOffset": len(blob) + len(blob_idx) + 48, "byteLength": 24}]
accessors = [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
              "min": [-1, -1, -1], "max": [1, 1, 1]},
             {"bufferView": 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
             {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [-30, -1, -30], "max": [30, -1, 30]},
             {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"}]
n = len(materials)
meshes = [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 0}, "indices": 1, "material": i}]}
          for i in range(n)]
meshes.append({"primitives": [{"attributes": {"POSITION": 2}, "indices": 3, "material": n}]})
spacing = 2.3
nodes = [{"mesh": i, "translation": [spacing * (i - (n - 1) / 2), 0, 0]} for i in range(n)]
nodes.append({"mesh": n})
width = spacing * n + 0.5
nodes.append({"camera": 0, "translation": [0, 0.8, 1.5 + width / (4 * math.tan(0.25))]})
used = sorted({k for m in materials for k in m.get("extensions", {})})
doc = {"asset": {"version": "2.0", "generator": "tools/make-gltf-sphere-row.py"},
       "buffers": [{"byteLength": len(bin_),
                    "uri": "data:application/octet-stream;base64," + base64.b64encode(bin_).decode()}],
       "bufferViews": views, "accessors": accessors,
       "materials": materials + [material((0.5, 0.5, 0.5), 0, 1, **LAMBERT)],
       "meshes": meshes, "nodes": nodes,
       "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1}}],
       "scenes": [{"nodes": list(range(len(nodes)))}], "scene": 0}
for i, m in enumerate(doc["materials"]):
    m["name"] = "floor" if i == n else "sphere%d" % i
if used: doc["extensionsUsed"] = used
with open(out, "w") as f:
    json.dump(doc, f)
