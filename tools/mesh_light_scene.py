#!/usr/bin/env python3
"""Write scenes/compare_cornell.toml with its quad light replaced by an
emitting mesh of the same rectangle and radiance, cut into N × N squares of
two triangles each (default 16: 512 triangles), for timing how an emitting
mesh is sampled against the quad light it tiles.

    python3 tools/mesh_light_scene.py [--cells N] [--out DIR]
    cargo run --release -- render DIR/cornell_mesh_light.toml --spp 512

Default DIR: the system's temporary directory/airlight-mesh-light. Needs
no packages beyond Python's own.
"""

import argparse
import os
import pathlib
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
# The light of scenes/compare_cornell.toml: emits toward edge_u × edge_v (down).
CORNER = (2.13, 5.487, 2.27)
EDGE_U = (1.3, 0.0, 0.0)
EDGE_V = (0.0, 0.0, 1.05)
RADIANCE = "[17.0, 12.0, 4.0]"


def light_obj(n):
    lines = []
    for a in range(n + 1):
        for b in range(n + 1):
            p = [CORNER[k] + EDGE_U[k] * a / n + EDGE_V[k] * b / n for k in range(3)]
            lines.append("v {:.6f} {:.6f} {:.6f}".format(*p))

    def vertex(a, b):
        return a * (n + 1) + b + 1

    for a in range(n):
        for b in range(n):
            # Counter-clockwise seen from below, as the quad light faces.
            lines.append(f"f {vertex(a, b)} {vertex(a + 1, b)} {vertex(a + 1, b + 1)}")
            lines.append(f"f {vertex(a, b)} {vertex(a + 1, b + 1)} {vertex(a, b + 1)}")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cells", type=int, default=16, help="squares along each edge (default 16)")
    parser.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "airlight-mesh-light"))
    args = parser.parse_args()
    if args.cells < 1:
        parser.error("--cells must be at least 1")
    source = (ROOT / "scenes" / "compare_cornell.toml").read_text()
    head, found, _ = source.partition("[[lights]]")
    if not found:
        raise SystemExit("scenes/compare_cornell.toml has no [[lights]] table")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "light.obj"), "w") as f:
        f.write(light_obj(args.cells))
    scene = head + f'[[objects]]\ntype = "mesh"\nfile = "light.obj"\nemission = {RADIANCE}\n'
    path = os.path.join(args.out, "cornell_mesh_light.toml")
    with open(path, "w") as f:
        f.write(scene)
    print(f"{path}: the Cornell box lit by {2 * args.cells * args.cells} emitting triangles")


if __name__ == "__main__":
    main()
