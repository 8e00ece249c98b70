#!/usr/bin/env python3
# Generates configs/metal-roughness.gltf: glTF's material on a grid of spheres, metallic 0, 0.5
# and 1 by row (bottom to top) and roughness 0, 0.25, 0.5, 0.75 and 1 by column, on a grey
# floor, with a camera. One sphere mesh (UV, with normals) is shared by every sphere's mesh.
# Usage: tools/make-gltf-spheres.py > configs/metal-roughness.gltf
import base64, json, math, struct

RINGS, SEGMENTS = 24, 48
METALLIC = [0.0, 0.5, 1.0]
ROUGHNESS = [0.0, 0.25, 0.5, 0.75, 1.0]

points, indices = [], []
for i in range(RINGS + 1):
    theta = math.pi * i / RINGS
    for j in range(SEGMENTS + 1):
        phi = 2 * math.pi * j / SEGMENTS
        points += [math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)]
for i in range(RINGS):
    for j in range(SEGMENTS):
        a = i * (SEGMENTS + 1) + j
        c = a + SEGMENTS + 1
        if i != 0:  # not the triangles collapsed to a point at the poles
            indices += [a, c, a + 1]
        if i != RINGS - 1:
            indices += [a + 1, c, c + 1]
floor = [-20, -1.1, -20, -20, -1.1, 20, 20, -1.1, 20, 20, -1.1, -20]
floor_indices = [0, 1, 2, 0, 2, 3]

parts = [struct.pack('<%df' % len(points), *points),
         struct.pack('<%dH' % len(indices), *indices),
         struct.pack('<%df' % len(floor), *floor),
         struct.pack('<%dH' % len(floor_indices), *floor_indices)]
blob, views = b'', []
for p in parts:
    blob += b'\0' * ((4 - len(blob) % 4) % 4)
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(p)})
    blob += p
vertices = len(points) // 3
doc = {
    "asset": {"version": "2.0", "generator": "tools/make-gltf-spheres.py"},
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": views,
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": vertices, "type": "VEC3",
         "min": [-1, -1, -1], "max": [1, 1, 1]},
        {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [-20, -1.1, -20], "max": [20, -1.1, 20]},
        {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "materials": [], "meshes": [], "nodes": [],
    "cameras": [{"type": "perspective", "name": "front",
                 "perspective": {"yfov": 0.55, "aspectRatio": 1.5, "znear": 0.1}}],
}
roots = []
for r, metallic in enumerate(METALLIC):
    for c, roughness in enumerate(ROUGHNESS):
        doc["materials"].append({"name": "metallic %g roughness %g" % (metallic, roughness),
                                 "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.64, 0.54, 1],
                                                          "metallicFactor": metallic,
                                                          "roughnessFactor": roughness}})
        doc["meshes"].append({"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 0},
                                              "indices": 1,
                                              "material": len(doc["materials"]) - 1}]})
        doc["nodes"].append({"mesh": len(doc["meshes"]) - 1,
                             "translation": [2.2 * c - 4.4, 2.2 * r, 0]})
        roots.append(len(doc["nodes"]) - 1)
doc["materials"].append({"name": "floor", "pbrMetallicRoughness": {
    "baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 0.8}})
doc["meshes"].append({"primitives": [{"attributes": {"POSITION": 2}, "indices": 3,
                                      "material": len(doc["materials"]) - 1}]})
doc["nodes"].append({"mesh": len(doc["meshes"]) - 1})
roots.append(len(doc["nodes"]) - 1)
# The camera at (0, 4, 15), looking down 12 degrees.
t = math.radians(-12) / 2
doc["nodes"].append({"camera": 0, "translation": [0, 4.2, 15],
                     "rotation": [math.sin(t), 0, 0, math.cos(t)]})
roots.append(len(doc["nodes"]) - 1)
doc["scenes"] = [{"nodes": roots}]
doc["scene"] = 0
print(json.dumps(doc, indent=1))
