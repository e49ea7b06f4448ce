"""Sweep the fog's scattering coefficient σs over ten values and see where
single scattering stops being enough.

For each σs the scene (built here from dicts, with the scene file's keys) is
rendered twice: by `raymarch`, which follows light scattered once in the fog,
and by the path tracer, which follows every bounce. The figure plots both
images' mean brightness and the relative RMSE of the ray marcher against the
path tracer over σs, and maps where the two differ at the densest fog.

    python docs/examples/sigma_s_sweep.py                      # docs/sigma_s_sweep.png
    python docs/examples/sigma_s_sweep.py --width 80 --height 60 --spp 16 -o /tmp/sweep.png

Needs the airlight wheel (crates/airlight-py), NumPy and matplotlib.
"""

import argparse
import time

import matplotlib

matplotlib.use("Agg")  # files only; no window
import matplotlib.pyplot as plt
import numpy as np

import airlight

SIGMA_S = np.linspace(0.0, 0.45, 10)


def scene(sigma_s, width, height):
    """A grey floor and sphere in fog, lit by a point light, all inside a
    black sphere so that no ray leaves the fog."""
    return airlight.Scene(
        {
            "render": {"width": width, "height": height, "max_depth": 16, "max_distance": 100.0},
            "camera": {"position": [0.0, 1.5, -5.0], "look_at": [0.0, 1.0, 0.0], "fov": 45.0},
            "medium": {"sigma_a": 0.03, "sigma_s": float(sigma_s), "g": 0.4},
            "materials": {"grey": {"albedo": 0.6}, "black": {"albedo": 0.0}},
            "objects": [
                {"type": "quad", "corner": [-4, 0, 4], "edge_u": [8, 0, 0], "edge_v": [0, 0, -8], "material": "grey"},
                {"type": "sphere", "center": [0.6, 0.7, 0.5], "radius": 0.7, "material": "grey"},
                {"type": "sphere", "center": [0, 0, 0], "radius": 12.0, "material": "black"},
            ],
            "lights": [{"type": "point", "position": [-0.8, 2.2, 0.0], "intensity": [8.0, 7.0, 6.0]}],
        }
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=120)
    parser.add_argument("--spp", type=int, default=64, help="samples per pixel of the path tracer")
    parser.add_argument("-o", "--output", default="docs/sigma_s_sweep.png")
    args = parser.parse_args()

    means, errors, last = {"raymarch": [], "path": []}, [], None
    start = time.monotonic()
    print(" σs     raymarch mean  path mean  rel. RMSE")
    for s in SIGMA_S:
        fog = scene(s, args.width, args.height)
        single = fog.render("raymarch", spp=4, steps=64)
        reference = fog.render("path", spp=args.spp)
        c = airlight.compare(single, reference)
        means["raymarch"].append(single.mean())
        means["path"].append(reference.mean())
        errors.append(c.rel_rmse)
        last = (s, single, reference)
        print(f"{s:5.3f}  {single.mean():13.5f}  {reference.mean():9.5f}  {c.rel_rmse:9.4f}")
    print(f"{len(SIGMA_S)} σs values, {time.monotonic() - start:.1f} s")

    s, single, reference = last
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    axes[0].plot(SIGMA_S, means["raymarch"], "o-", label="raymarch (single scattering)")
    axes[0].plot(SIGMA_S, means["path"], "s-", label=f"path tracer ({args.spp} spp)")
    axes[0].set(xlabel="σs (1/unit)", ylabel="image mean (linear RGB)", title="Brightness")
    axes[0].legend()
    axes[1].plot(SIGMA_S, errors, "o-", color="C3")
    axes[1].set(xlabel="σs (1/unit)", ylabel="relative RMSE", title="raymarch against the path tracer")
    # The path tracer's image, as a PNG would show it (2.2 gamma, clipped).
    axes[2].imshow(np.clip(reference, 0, 1) ** (1 / 2.2))
    axes[2].set(title=f"path tracer at σs = {s:.2f}", xticks=[], yticks=[])
    # Where single scattering falls short, averaged over blocks of 4×4
    # pixels so that the path tracer's noise does not hide it.
    diff = (reference - single).mean(axis=2)
    h, w = (d - d % 4 for d in diff.shape)
    blocks = diff[:h, :w].reshape(h // 4, 4, w // 4, 4).mean(axis=(1, 3)) if h and w else diff
    im = axes[3].imshow(blocks, cmap="magma", vmin=0, vmax=np.percentile(blocks, 99))
    axes[3].set(title="path − raymarch, 4×4 px blocks", xticks=[], yticks=[])
    fig.colorbar(im, ax=axes[3], fraction=0.04)
    fig.tight_layout()
    fig.savefig(args.output, dpi=80)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
