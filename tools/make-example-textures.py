#!/usr/bin/env python3
"""Writes the images and the mesh of configs/textured-sky.json into assets/textures/ (git-ignored):
a lat-long sky with a sun (PFM, linear radiance), tiles, marble and a leaf mask (8-bit PNG,
sRGB), a bump map (8-bit grey PNG, linear) and a UV sphere with texture coordinates and
normals (OBJ). Everything is computed here from formulas, in plain Python (no packages beyond
the standard library), and is the same on every run. tools/fetch-assets.sh calls it.

    tools/make-example-textures.py [OUTPUT_DIR]     (default assets/textures)
"""
import math
import os
import struct
import sys
import zlib


def write_png(path, width, height, channels, pixel):
    """An 8-bit PNG; pixel(x, y) gives `channels` values in [0, 1] (row 0 at the top)."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)  # no filter
        for x in range(width):
            for v in pixel(x, y):
                rows.append(max(0, min(255, int(round(v * 255.0)))))
    colour_type = {1: 0, 3: 2, 4: 6}[channels]

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    data = (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(bytes(rows), 9)) + chunk(b"IEND", b""))
    write_atomically(path, data)


def write_pfm(path, width, height, pixel):
    """A little-endian RGB PFM (rows stored bottom to top); pixel(x, y), row 0 at the top."""
    body = bytearray()
    for y in reversed(range(height)):
        for x in range(width):
            body += struct.pack("<fff", *pixel(x, y))
    write_atomically(path, b"PF\n%d %d\n-1.0\n" % (width, height) + bytes(body))


def write_atomically(path, data):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def srgb_encode(linear):
    linear = max(0.0, min(1.0, linear))
    return 12.92 * linear if linear <= 0.0031308 else 1.055 * linear ** (1 / 2.4) - 0.055


def sky(x, y, width, height):
    """Radiance of a clear sky with a sun, lat-long: u = phi / 2 pi, v = theta / pi from +y."""
    theta = math.pi * (y + 0.5) / height
    phi = 2.0 * math.pi * (x + 0.5) / width
    # The JSON format's lat-long directions: +y up, u = 1/2 looking along -z, u = 3/4 along +x.
    d = (-math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi))
    sun = (-0.5, 0.6, 0.62)
    n = math.sqrt(sum(c * c for c in sun))
    sun = tuple(c / n for c in sun)
    cos_sun = sum(a * b for a, b in zip(d, sun))
    if d[1] < 0.0:  # the ground below the horizon: a dim brown
        g = 0.25 + 0.1 * math.exp(8.0 * d[1])
        return (0.28 * g, 0.22 * g, 0.16 * g)
    # Blue overhead, whiter towards the horizon, a glow about the sun.
    horizon = math.exp(-6.0 * d[1])
    r = 0.25 + 0.55 * horizon
    g = 0.42 + 0.45 * horizon
    b = 0.85 + 0.15 * horizon
    glow = 2.0 * math.exp(60.0 * (cos_sun - 1.0))
    # The sun: a disc of 2 degrees' radius, bright (most of the direct light comes from it).
    disc = 2000.0 if cos_sun > math.cos(math.radians(2.0)) else 0.0
    return (r + glow + disc, g + 0.9 * glow + 0.95 * disc, b + 0.7 * glow + 0.85 * disc)


def tiles(x, y, size=256):
    """Terracotta tiles with light grout, 4 x 4 per image, each tile a slightly different shade."""
    tile = size // 4
    tx, ty = x // tile, y // tile
    fx, fy = x % tile, y % tile
    if fx < 3 or fy < 3:
        return tuple(srgb_encode(v) for v in (0.55, 0.53, 0.5))
    shade = 0.85 + 0.15 * math.sin(12.9898 * tx + 78.233 * ty) ** 2
    speck = 0.04 * math.sin(0.9 * x + 1.7 * y) * math.sin(1.3 * x - 0.7 * y)
    return tuple(srgb_encode(v * shade + speck) for v in (0.45, 0.16, 0.08))


def marble(x, y, size=256):
    """Veined marble from nested sines (periodic in both directions, so it tiles)."""
    u, v = 2.0 * math.pi * x / size, 2.0 * math.pi * y / size
    turbulence = (math.sin(3 * u + math.sin(2 * v)) + 0.5 * math.sin(7 * v + 2 * math.sin(3 * u)) +
                  0.25 * math.sin(13 * u + 5 * v))
    vein = abs(math.sin(2 * u + 3 * v + 2.5 * turbulence)) ** 0.35
    base = (0.82, 0.8, 0.76)
    dark = (0.25, 0.3, 0.35)
    return tuple(srgb_encode(d + (b - d) * vein) for b, d in zip(base, dark))


def bumps(x, y, size=128):
    """Rounded bumps in a 4 x 4 grid, as heights in [0, 1] (a linear grey image)."""
    cell = size / 4.0
    fx = (x + 0.5) % cell / cell - 0.5
    fy = (y + 0.5) % cell / cell - 0.5
    r2 = (fx * fx + fy * fy) * 4.0
    return (max(0.0, 1.0 - r2) ** 2,)


def leaves(x, y, size=256):
    """Green leaves (ellipses in a staggered grid) with alpha 1 on them and 0 between."""
    cell = size / 4.0
    row = int(y // cell)
    shift = 0.5 * cell * (row % 2)
    fx = ((x + 0.5 + shift) % cell) / cell - 0.5
    fy = ((y + 0.5) % cell) / cell - 0.5
    a, b = fx * math.cos(0.6) + fy * math.sin(0.6), -fx * math.sin(0.6) + fy * math.cos(0.6)
    inside = (a / 0.45) ** 2 + (b / 0.22) ** 2 < 1.0
    vein = 0.7 + 0.3 * min(1.0, abs(b) * 12.0)
    colour = (0.12 * vein, 0.42 * vein, 0.08 * vein)
    return tuple(srgb_encode(c) for c in colour) + ((1.0 if inside else 0.0),)


def write_sphere(path, rings=48, segments=96):
    """A unit UV sphere: v, vt (u = phi / 2 pi, v = 1 - theta / pi) and vn, outward winding."""
    lines = ["# UV sphere written by tools/make-example-textures.py"]
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            p = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            lines.append("v %.7f %.7f %.7f" % p)
            lines.append("vn %.7f %.7f %.7f" % p)
            lines.append("vt %.7f %.7f" % (j / segments, 1.0 - i / rings))
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j + 1
            b, c, d = a + 1, a + segments + 1, a + segments + 2
            if i != 0:
                lines.append("f %d/%d/%d %d/%d/%d %d/%d/%d" % (a, a, a, c, c, c, b, b, b))
            if i != rings - 1:
                lines.append("f %d/%d/%d %d/%d/%d %d/%d/%d" % (b, b, b, c, c, c, d, d, d))
    write_atomically(path, ("\n".join(lines) + "\n").encode())


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "assets", "textures")
    os.makedirs(out, exist_ok=True)
    write_pfm(os.path.join(out, "sky.pfm"), 512, 256, lambda x, y: sky(x, y, 512, 256))
    write_png(os.path.join(out, "tiles.png"), 256, 256, 3, tiles)
    write_png(os.path.join(out, "marble.png"), 256, 256, 3, marble)
    write_png(os.path.join(out, "bumps.png"), 128, 128, 1, bumps)
    write_png(os.path.join(out, "leaves.png"), 256, 256, 4, leaves)
    write_sphere(os.path.join(out, "sphere.obj"))
    print("make-example-textures: wrote sky.pfm, tiles.png, marble.png, bumps.png, leaves.png, "
          "sphere.obj in " + os.path.normpath(out))


if __name__ == "__main__":
    main()
