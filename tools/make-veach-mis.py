#!/usr/bin/env python3
# Generates configs/veach-mis.json: four plates of increasing roughness lit by four spherical
# lights of increasing size and equal power, in the manner of Veach's MIS test (our own
# geometry). Usage: tools/make-veach-mis.py > configs/veach-mis.json
import json, math, sys

# Small vector helpers (lists of three floats).
def sub(a,b): return [a[i]-b[i] for i in range(3)]
def add(a,b): return [a[i]+b[i] for i in range(3)]
def mul(a,s): return [a[i]*s for i in range(3)]
def dot(a,b): return sum(a[i]*b[i] for i in range(3))
def cross(a,b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
def norm(a): l=math.sqrt(dot(a,a)); return [x/l for x in a]
def length(a): return math.sqrt(dot(a,a))
def mean(ps): return [sum(p[i] for p in ps)/len(ps) for i in range(3)]


plate_material = sys.argv[1] if len(sys.argv) > 1 else None  # override for layout checks
C = [0.0, 3.5, 10.0]            # camera
T = [0.0, 2.3, 0.0]            # target
LY, LZ = 4.6, -2.2             # light row height and depth
LX = [-3.3, -1.1, 1.1, 3.3]
RADII = [0.03, 0.1, 0.3, 0.9]
ALPHAS = [0.005, 0.02, 0.05, 0.1]   # top (farthest) plate smoothest
W, D = 9.0, 1.4                # plate length (x) and depth

def r6(x): return float('%.6g' % x)
def pt(p): return [r6(c) for c in p]

def sphere(center, radius, rings, segments):
    verts = [add(center, [0, radius, 0])]
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(segments):
            ph = 2 * math.pi * j / segments
            verts.append(add(center, mul([math.sin(th) * math.cos(ph), math.cos(th),
                                          math.sin(th) * math.sin(ph)], radius)))
    verts.append(add(center, [0, -radius, 0]))
    top, bottom = 0, len(verts) - 1
    def ring(i, j): return 1 + (i - 1) * segments + (j % segments)
    tris = []
    for j in range(segments):
        tris.append([top, ring(1, j + 1), ring(1, j)])
        tris.append([bottom, ring(rings - 1, j), ring(rings - 1, j + 1)])
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            tris.append([a, b, c])
            tris.append([a, c, d])
    # outward winding check
    for t in tris:
        v0, v1, v2 = (verts[k] for k in t)
        n = cross(sub(v1, v0), sub(v2, v0))
        assert dot(n, sub(mean([v0, v1, v2]), center)) > 0
    area = sum(length(cross(sub(verts[t[1]], verts[t[0]]), sub(verts[t[2]], verts[t[0]]))) / 2
               for t in tris)
    return verts, tris, area

materials = [
    {"name": "floor", "type": "diffuse", "reflectance": [0.4, 0.4, 0.4]},
    {"name": "wall", "type": "diffuse", "reflectance": [0.3, 0.3, 0.3]},
    {"name": "fill", "type": "diffuse", "reflectance": [0, 0, 0], "emission": [0.08, 0.08, 0.08]},
]
for i, a in enumerate(ALPHAS):
    if plate_material:
        materials.append({"name": "plate%d" % i, "type": plate_material})
    else:
        materials.append({"name": "plate%d" % i, "type": "conductor",
                          "reflectance": [0.8, 0.8, 0.8], "roughness": a,
                          "remaproughness": False})
shapes = [
    {"type": "quad", "name": "floor", "material": "floor",
     "vertices": [[-12, 0, -5], [-12, 0, 12], [12, 0, 12], [12, 0, -5]]},
    {"type": "quad", "name": "back wall", "material": "wall",
     "vertices": [[-12, 0, -5], [12, 0, -5], [12, 20, -5], [-12, 20, -5]]},
    # Above the camera, facing down; the plates reflect the lights, not this.
    {"type": "quad", "name": "fill light", "material": "fill",
     "vertices": [[-6, 9, 4], [6, 9, 4], [6, 9, 12], [-6, 9, 12]]},
]

Lc = [0.0, LY, LZ]
# Plates from the nearest and lowest (roughest, i = 3) to the farthest and highest (smoothest,
# i = 0), each tilted so that the camera sees the light row mirrored at its centre.
plates = []
for k in range(4):
    i = 3 - k
    P = [0.0, 0.55 + 0.6 * k, 2.8 - 1.3 * k]
    n = norm(add(norm(sub(C, P)), norm(sub(Lc, P))))
    s = norm(cross(n, [1, 0, 0]))   # the plate's short axis, in the y-z plane
    ex, es = [W / 2, 0, 0], mul(s, D / 2)
    v = [add(add(P, mul(ex, -1)), mul(es, -1)), add(add(P, ex), mul(es, -1)),
         add(add(P, ex), es), add(add(P, mul(ex, -1)), es)]
    nn = cross(sub(v[1], v[0]), sub(v[2], v[0]))
    if dot(nn, n) < 0: v = v[::-1]
    shapes.append({"type": "quad", "name": "plate %d (alpha %g)" % (i, ALPHAS[i]),
                   "material": "plate%d" % i, "vertices": [pt(p) for p in v]})
    plates.append((P, n))

# Equal power: a one-sided Lambertian emitter of radiance L and area A emits pi L A, so each
# light's radiance is inversely proportional to its (tessellated) area.
POWER_RADIANCE_AREA = 2.0 * 4 * math.pi * 0.9 ** 2  # the largest light has radiance about 2
for i, (x, r) in enumerate(zip(LX, RADII)):
    verts, tris, area = sphere([x, LY, LZ], r, 8, 16)
    L = POWER_RADIANCE_AREA / area
    materials.append({"name": "light%d" % i, "type": "diffuse", "reflectance": [0, 0, 0],
                      "emission": [r6(L)] * 3})
    shapes.append({"type": "triangles", "name": "light %d (radius %g)" % (i, r),
                   "material": "light%d" % i, "vertices": [pt(p) for p in verts],
                   "indices": tris})

scene = {
    "description": "In the manner of Veach's multiple importance sampling test (our own geometry): "
                   "four long plates of rough metal (conductor, reflectance 0.8, Trowbridge-Reitz "
                   "alpha 0.1, 0.05, 0.02 and 0.005 from the bottom up, remaproughness off) "
                   "reflecting four spherical lights of radius 0.03, 0.1, 0.3 and 0.9 (UV spheres "
                   "of 224 triangles) that emit the same power, over a floor and before a back "
                   "wall, with a dim fill light above the camera",
    "camera": {"position": C, "target": T, "up": [0, 1, 0], "vfov": 40, "width": 384,
               "height": 256},
    "integrator": {"spp": 64, "maxDepth": 16, "seed": 0, "russianRoulette": True,
                   "rrStartDepth": 3, "strategy": "mis"},
    "materials": materials,
    "shapes": shapes,
}

# One line per material and shape, vertices and indices inline: readable and diffable.
out = ['{']
for key in ["description", "camera", "integrator"]:
    out.append('  %s: %s,' % (json.dumps(key), json.dumps(scene[key])))
out.append('  "materials": [')
out.append(',\n'.join('    ' + json.dumps(m) for m in materials))
out.append('  ],')
out.append('  "shapes": [')
out.append(',\n'.join('    ' + json.dumps(sh) for sh in shapes))
out.append('  ]')
out.append('}')
sys.stdout.write('\n'.join(out) + '\n')
