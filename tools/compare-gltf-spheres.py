# Compares two renders of a scene of tools/make-gltf-sphere-row.py (pt's and Cycles', EXR)
# region by region: the mean RGB over the middle of each sphere's disc (a square of 0.8 of its
# projected radius), over a strip of the floor in front of them and over the sky, and their
# relative differences. Run by Blender's Python, which reads EXR (docs/gltf.md, "Against Cycles").
# Usage: blender -b --python tools/compare-gltf-spheres.py -- scene.gltf ours.exr cycles.exr
import json
import math
import sys

import bpy
import numpy

scene_file, ours_file, theirs_file = sys.argv[sys.argv.index("--") + 1:]
doc = json.load(open(scene_file))


def pixels(path):
    image = bpy.data.images.load(path)
    w, h = image.size
    a = numpy.array(image.pixels[:], dtype=numpy.float64).reshape(h, w, 4)[::-1, :, :3]
    return a  # row 0 at the top


ours, theirs = pixels(ours_file), pixels(theirs_file)
h, w = ours.shape[:2]
camera = next(n for n in doc["nodes"] if "camera" in n)["translation"]
t = math.tan(doc["cameras"][0]["perspective"]["yfov"] / 2)
aspect = w / h


def project(x, y, z):
    dz = camera[2] - z
    u = (x - camera[0]) / dz / (t * aspect)
    v = (y - camera[1]) / dz / t
    return (u + 1) / 2 * w, (1 - v) / 2 * h


regions = []
spheres = [n for n in doc["nodes"] if "mesh" in n and "translation" in n]
for i, n in enumerate(spheres):
    cx, cy = project(*n["translation"])
    r = 0.4 * h / 2 / (camera[2] - n["translation"][2]) / t
    regions.append(("sphere %d" % i, int(cy - r), int(cy + r) + 1, int(cx - r), int(cx + r) + 1))
fx, fy = project(0, -1, 2.0)
regions.append(("floor", int(fy) - 2, int(fy) + 3, w // 4, 3 * w // 4))
regions.append(("sky", 0, max(1, h // 10), 0, w))
for name, y0, y1, x0, x1 in regions:
    a = ours[y0:y1, x0:x1].reshape(-1, 3).mean(axis=0)
    b = theirs[y0:y1, x0:x1].reshape(-1, 3).mean(axis=0)
    rel = (a - b) / numpy.maximum(b, 1e-6)
    print("REGION %-9s pt %s cycles %s relative %s" % (
        name, numpy.array2string(a, precision=4), numpy.array2string(b, precision=4),
        numpy.array2string(rel, precision=3, sign="+")))
