"""Writes a large glTF binary (.glb) for the loading benchmark in
BENCHMARKS.md: a rolling terrain of N×N squares (2·N² triangles, indexed,
u32 indices, with TEXCOORD_0), a point light above it and a camera.

    python3 tools/make_large_glb.py OUT.glb [--n 710]      # 710: 1,008,200 triangles

Standard library only (struct, array, json).
"""

import argparse
import array
import json
import math
import struct


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("--n", type=int, default=710, help="squares per side")
    args = parser.parse_args()
    n = args.n
    size = 20.0

    positions = array.array("f")
    uvs = array.array("f")
    for j in range(n + 1):
        for i in range(n + 1):
            x = size * (i / n - 0.5)
            z = size * (j / n - 0.5)
            y = 0.4 * math.sin(0.9 * x) * math.cos(0.7 * z) + 0.15 * math.sin(2.3 * x + 1.7 * z)
            positions.extend((x, y, z))
            uvs.extend((i / n, j / n))
    indices = array.array("I")
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            # Counter-clockwise seen from above (+y).
            indices.extend((a, c, b, b, c, d))
    for a in (positions, uvs, indices):
        if a.itemsize != 4:
            raise SystemExit("needs 4-byte floats and unsigned ints")
    if struct.pack("=I", 1) != struct.pack("<I", 1):
        positions.byteswap()
        uvs.byteswap()
        indices.byteswap()

    blobs = [positions.tobytes(), uvs.tobytes(), indices.tobytes()]
    views, offset = [], 0
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        offset += len(blob)
    ys = positions[1::3]
    gltf = {
        "asset": {"version": "2.0", "generator": "airlight tools/make_large_glb.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"name": "terrain", "mesh": 0},
            {"name": "lamp", "translation": [0, 4, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "eye", "translation": [0, 6, 14], "rotation": [-0.2164396, 0, 0, 0.9762960], "camera": 0},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1}}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 20000}]}},
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.55, 0.5, 1]}}],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}
        ],
        "buffers": [{"byteLength": offset}],
        "bufferViews": views,
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": (n + 1) ** 2,
                "type": "VEC3",
                "min": [-size / 2, min(ys), -size / 2],
                "max": [size / 2, max(ys), size / 2],
            },
            {"bufferView": 1, "componentType": 5126, "count": (n + 1) ** 2, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": len(indices), "type": "SCALAR"},
        ],
    }
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    binary = b"".join(blobs)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    with open(args.out, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", len(binary), b"BIN\0") + binary)
    print(f"{args.out}: {2 * n * n} triangles, {(n + 1) ** 2} vertices, {total / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
