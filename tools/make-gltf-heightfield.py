#!/usr/bin/env python3
# Writes a large glTF for measuring the reader: an N x N heightfield mesh (2 N^2 triangles) with
# normals and texture coordinates, used by four nodes, as a .glb (docs/gltf.md, "Loading a large
# model"). Usage: tools/make-gltf-heightfield.py 500 big.glb
import json, struct, math, sys
N = int(sys.argv[1]); out = sys.argv[2]
pos = bytearray(); nrm = bytearray(); uv = bytearray(); idx = bytearray()
for j in range(N + 1):
    for i in range(N + 1):
        x = i / N * 2 - 1; z = j / N * 2 - 1
        y = 0.1 * math.sin(6 * x) * math.cos(6 * z)
        dx = 0.6 * math.cos(6 * x) * math.cos(6 * z); dz = -0.6 * math.sin(6 * x) * math.sin(6 * z)
        l = math.sqrt(dx * dx + 1 + dz * dz)
        pos += struct.pack('<3f', x, y, z); nrm += struct.pack('<3f', -dx / l, 1 / l, -dz / l)
        uv += struct.pack('<2f', i / N, j / N)
for j in range(N):
    for i in range(N):
        a = j * (N + 1) + i; b = a + 1; c = a + N + 1; d = c + 1
        idx += struct.pack('<6I', a, c, b, b, c, d)
bin = pos + nrm + uv + idx
nv = (N + 1) ** 2
views = []; off = 0
for part in (pos, nrm, uv, idx):
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(part)}); off += len(part)
doc = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(bin)}], "bufferViews": views,
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3"},
                {"bufferView": 2, "componentType": 5126, "count": nv, "type": "VEC2"},
                {"bufferView": 3, "componentType": 5125, "count": 6 * N * N, "type": "SCALAR"}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1], "metallicFactor": 0.3, "roughnessFactor": 0.4}}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
  "nodes": [{"mesh": 0, "translation": [2.2 * (k % 2), 0, 2.2 * (k // 2)]} for k in range(4)],
  "scenes": [{"nodes": [0, 1, 2, 3]}], "scene": 0}
j = json.dumps(doc).encode(); j += b' ' * ((4 - len(j) % 4) % 4)
bin += b'\0' * ((4 - len(bin) % 4) % 4)
with open(out, 'wb') as f:
    f.write(b'glTF' + struct.pack('<II', 2, 12 + 8 + len(j) + 8 + len(bin)))
    f.write(struct.pack('<I', len(j)) + b'JSON' + j + struct.pack('<I', len(bin)) + b'BIN\0' + bin)
