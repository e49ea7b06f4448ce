"""The CLI's multi-layer AOV EXR read back with the OpenEXR package (the
reference implementation's Python bindings): the standard channel names,
and values equal to those of this suite's own reader (exr.py, which shares
no code with Airlight or OpenEXR) and as the scene makes them."""

import numpy as np
import pytest
from conftest import SCENES
from exr import read_channels

OpenEXR = pytest.importorskip("OpenEXR")

NAMES = {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "N.X", "N.Y", "N.Z", "Z"}
NAMES |= {"inscatter.R", "inscatter.G", "inscatter.B"}


def test_openexr_reads_the_aov_layers(cli, tmp_path):
    out = tmp_path / "aov.exr"
    cli(
        "render", SCENES / "models" / "blender_room.glb",
        "--medium", "sigma_s=0.08,sigma_a=0.01,g=0.3", "--integrator", "raymarch", "--steps", "8",
        "--width", "32", "--height", "24", "--spp", "2", "-q",
        "--aov", "albedo,normal,depth,inscatter", "-o", out,
    )
    with OpenEXR.File(str(out), separate_channels=True) as f:
        channels = {name: np.asarray(c.pixels, dtype=np.float32) for name, c in f.channels().items()}
    assert set(channels) == NAMES
    assert all(c.shape == (24, 32) for c in channels.values())
    # The same numbers as an independent reader finds.
    ours = read_channels(out)
    for name in NAMES:
        np.testing.assert_array_equal(channels[name], np.asarray(ours[name]).reshape(24, 32), err_msg=name)
    # Normals are means of unit vectors over a pixel's samples (shorter at
    # edges and the horizon, zero where all miss); the bottom row sees only
    # the floor: straight up. Depth is positive where anything is seen.
    seen = np.isfinite(channels["Z"])
    assert seen[-1].all() and not seen.all()
    length = np.linalg.norm(np.stack([channels["N.X"], channels["N.Y"], channels["N.Z"]]), axis=0)
    assert (length <= 1 + 1e-5).all() and (length[~seen] == 0).all()
    np.testing.assert_allclose(channels["N.Y"][-1], 1.0, atol=1e-5)
    assert (channels["Z"][seen] > 0).all()
    # Albedos are reflectances; the fog's light is part of the image.
    for c in "RGB":
        assert ((channels[f"albedo.{c}"] >= 0) & (channels[f"albedo.{c}"] <= 1)).all()
        assert (channels[f"inscatter.{c}"] > 0).all()
        assert (channels[f"inscatter.{c}"] <= channels[c] * (1 + 1e-5)).all()
