#!/usr/bin/env python3
# Generates configs/water-caustic.json: a small lamp above a pool whose rippled water surface
# (a smooth dielectric, eta 1.33, as a faceted height field) focuses its light into caustics on
# the diffuse pool floor, seen from above through the water: light paths of the kind L S D S E
# that path tracing finds only by chance and photon mapping (sppm) was made for.
# Usage: tools/make-water-caustic.py > configs/water-caustic.json
import json, math, re

N = 24            # height-field cells per side
HALF = 2.0        # the pool spans [-HALF, HALF] in x and z
LEVEL = 1.0       # the water's mean height above the floor
AMPLITUDE = 0.04  # the ripples' height


def r6(x):
    return float('%.6g' % x)


def height(x, z):
    return LEVEL + AMPLITUDE * (math.sin(2.7 * x + 0.5 * z) + 0.7 * math.sin(3.9 * z - 1.3 * x + 1.0)
                                + 0.4 * math.sin(6.1 * x + 5.3 * z))


vertices, indices = [], []
for j in range(N + 1):
    for i in range(N + 1):
        x = -HALF + 2 * HALF * i / N
        z = -HALF + 2 * HALF * j / N
        vertices.append([r6(x), r6(height(x, z)), r6(z)])
for j in range(N):
    for i in range(N):
        a = j * (N + 1) + i
        b, c, d = a + 1, a + N + 1, a + N + 2
        # Counter-clockwise seen from above: the geometric normal points up, out of the water.
        indices += [[a, c, b], [b, c, d]]

H = 1.3  # the pool's walls
scene = {
    "description": "A small lamp above a pool: its rippled water surface (smooth dielectric, "
                   "eta 1.33, a faceted height field) throws caustics on the diffuse floor, seen "
                   "through the water. Made by tools/make-water-caustic.py.",
    "camera": {"position": [0, 3.6, -3.2], "target": [0, 0, 0.2], "up": [0, 1, 0], "vfov": 45,
               "width": 128, "height": 128},
    "integrator": {"spp": 64, "maxDepth": 8},
    "materials": [
        {"name": "tiles", "type": "diffuse", "reflectance": [0.6, 0.65, 0.7]},
        {"name": "wall", "type": "diffuse", "reflectance": [0.5, 0.5, 0.5]},
        {"name": "water", "type": "dielectric", "eta": 1.33},
        {"name": "lamp", "type": "diffuse", "reflectance": [0, 0, 0], "emission": [400, 380, 340]},
    ],
    "shapes": [
        {"type": "quad", "name": "floor", "material": "tiles",
         "vertices": [[-HALF, 0, -HALF], [-HALF, 0, HALF], [HALF, 0, HALF], [HALF, 0, -HALF]]},
        {"type": "quad", "name": "wall -x", "material": "wall",
         "vertices": [[-HALF, 0, -HALF], [-HALF, H, -HALF], [-HALF, H, HALF], [-HALF, 0, HALF]]},
        {"type": "quad", "name": "wall +x", "material": "wall",
         "vertices": [[HALF, 0, HALF], [HALF, H, HALF], [HALF, H, -HALF], [HALF, 0, -HALF]]},
        {"type": "quad", "name": "wall +z", "material": "wall",
         "vertices": [[-HALF, 0, HALF], [-HALF, H, HALF], [HALF, H, HALF], [HALF, 0, HALF]]},
        {"type": "quad", "name": "wall -z", "material": "wall",
         "vertices": [[HALF, 0, -HALF], [HALF, H, -HALF], [-HALF, H, -HALF], [-HALF, 0, -HALF]]},
        {"type": "triangles", "name": "water surface", "material": "water",
         "vertices": vertices, "indices": indices},
        {"type": "quad", "name": "lamp", "material": "lamp",
         "vertices": [[0.5, 3.0, 0.3], [0.7, 3.0, 0.3], [0.7, 3.0, 0.5], [0.5, 3.0, 0.5]]},
    ],
}
# One line per point and per triangle.
text = json.dumps(scene, indent=1)
text = re.sub(r"\[\s*(-?[\d.e-]+),\s*(-?[\d.e-]+),\s*(-?[\d.e-]+)\s*\]", r"[\1, \2, \3]", text)
print(text)
