#!/usr/bin/env python3
"""Renders one scene with several seeds per build of Airlight and prints how
the renders spread: the noise of one render, without a reference.

    python3 tools/seed_spread.py --scene scenes/compare_fog_point.toml \\
        --spp 64 --seeds 24 OLD_BINARY NEW_BINARY [-- MORE RENDER OPTIONS]

Per build: the image mean over all renders; the relative variance of one
render (each pixel's variance across the seeds, averaged over the pixels,
over the mean squared: time × this is what equal-error comparisons weigh);
the same with each pixel's largest value left out, which shows how much of
the variance rare, bright pixels (fireflies) carry; and how many pixels per
render exceed ten times their median over the seeds. Seeds 1..N are the
same for every build, so two builds see the same sample points where
their estimators agree.

Reads the EXRs with Mitsuba's `Bitmap` (needs `numpy` and `mitsuba`, as
tools/mitsuba_compare.py).
"""

import argparse
import os
import subprocess
import sys
import tempfile

import mitsuba as mi
import numpy as np


def renders(binary: str, scene: str, spp: int, seeds: int, out: str, more: list) -> np.ndarray:
    images = []
    for seed in range(1, seeds + 1):
        path = os.path.join(out, f"seed{seed}.exr")
        command = [binary, "render", scene, "--spp", str(spp), "--seed", str(seed), "-o", path, "--quiet", *more]
        subprocess.run(command, check=True)
        images.append(np.array(mi.Bitmap(path), dtype=np.float64)[..., :3])
    return np.array(images)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("binaries", nargs="+")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--seeds", type=int, default=16)
    # What follows `--` goes to every render.
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    args = parser.parse_args(argv[:split])
    more = argv[split + 1 :]
    mi.set_variant("scalar_rgb")
    for binary in args.binaries:
        with tempfile.TemporaryDirectory() as out:
            images = renders(binary, args.scene, args.spp, args.seeds, out, more)
        mean = images.mean()
        variance = images.var(axis=0, ddof=1).mean() / mean**2
        trimmed = np.sort(images, axis=0)[:-1].var(axis=0, ddof=1).mean() / mean**2
        brightest = images.max(axis=-1)
        ratio = brightest / np.maximum(np.median(brightest, axis=0), 0.05)
        fireflies = np.mean([(r > 10).sum() for r in ratio])
        print(
            f"{binary}: {args.seeds} renders at {args.spp} spp, mean {mean:.5f}, "
            f"relative variance {variance:.5f} (rel. RMSE {np.sqrt(variance):.4f}), "
            f"without each pixel's largest {trimmed:.5f}, pixels above 10x their median per render {fireflies:.2f}"
        )


if __name__ == "__main__":
    main()
