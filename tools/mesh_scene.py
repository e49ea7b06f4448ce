#!/usr/bin/env python3
"""Write the 1.1 M-triangle mesh scene that the ray-throughput comparison
with Mitsuba uses: the displaced UV sphere of `examples/bench_bvh.rs`
(SUBDIVISIONS² quads, default 750² → 1,125,000 triangles, radius modulated
by a sum of sines), lit by one point light, rendered with direct light at
1024×1024 (a camera ray and a shadow ray per sample).

    python3 tools/mesh_scene.py [--subdivisions N] [--out DIR]
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
        python3 tools/mitsuba_compare.py --spp 1 DIR/compare_mesh.toml

The OBJ is about 60 MB, so it is generated rather than kept in the
repository (default DIR: the system's temporary directory/airlight-mesh).
"""

import argparse
import os
import tempfile

import numpy as np


def displaced_sphere(n):
    theta = np.pi * np.arange(n + 1) / n
    phi = 2.0 * np.pi * np.arange(n + 1) / n
    t, p = np.meshgrid(theta, phi, indexing="ij")
    r = 1.0 + 0.05 * np.sin(7.0 * t) * np.sin(9.0 * p) + 0.02 * np.sin(31.0 * t + 3.0 * p)
    positions = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], axis=-1) * r[..., None]
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b = a + n + 1
    triangles = np.concatenate([np.stack([a, b, a + 1], 1), np.stack([a + 1, b, b + 1], 1)])
    return positions.reshape(-1, 3), triangles


SCENE = """# A displaced sphere of {count} triangles under a point light, direct
# light only: the ray-throughput comparison with Mitsuba (tools/mesh_scene.py).
[render]
width = 1024
height = 1024
integrator = "direct"
spp = 1

[camera]
position = [0.0, 0.6, -3.2]
look_at = [0.0, 0.0, 0.0]
fov = 40.0

[materials.grey]
albedo = 0.7

[[objects]]
type = "mesh"
file = "displaced_sphere.obj"
material = "grey"

[[lights]]
type = "point"
position = [2.0, 3.0, -3.0]
intensity = 20.0
"""


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--subdivisions", type=int, default=750)
    p.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "airlight-mesh"))
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    positions, triangles = displaced_sphere(args.subdivisions)
    with open(os.path.join(args.out, "displaced_sphere.obj"), "w") as f:
        np.savetxt(f, positions, fmt="v %.7g %.7g %.7g")
        np.savetxt(f, triangles + 1, fmt="f %d %d %d")
    with open(os.path.join(args.out, "compare_mesh.toml"), "w") as f:
        f.write(SCENE.format(count=len(triangles)))
    print(os.path.join(args.out, "compare_mesh.toml"))


if __name__ == "__main__":
    main()
