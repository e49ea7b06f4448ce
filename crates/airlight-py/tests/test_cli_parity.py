"""The same scene rendered from Python and by the `airlight` CLI gives the
same pixels, bit for bit; `compare` gives the CLI's figures."""

import tomllib

import numpy as np
import pytest
from conftest import SCENES
from exr import read_channels, read_exr

import airlight

SIZE = dict(width=48, height=32)

# (scene, CLI options, the same as render() arguments): every integrator.
CASES = [
    ("spheres_point_fog.toml", [], {}),
    ("fog_lights_height.toml", ["--seed", "7", "--steps", "16"], dict(seed=7, steps=16)),
    ("glow.toml", ["--integrator", "analytic", "--light-steps", "4"], dict(integrator="analytic", light_steps=4)),
    ("shadow_spheres.toml", ["--shadows", "--light-quadrature", "uniform"], dict(shadows=True, light_quadrature="uniform")),
    ("spot_spheres.toml", ["--integrator", "path", "--spp", "2"], dict(integrator="path", spp=2)),
    ("compare_spot_hard.toml", ["--spp", "3"], dict(spp=3)),
    ("sdf_isometric.toml", ["--sampling", "mis", "--no-stratify"], dict(sampling="mis", stratify=False)),
    ("four_lights.toml", ["--spp", "2"], dict(spp=2)),
    ("cornell_box.toml", ["--spp", "2"], dict(spp=2)),
]


def cli_render(cli, tmp_path, scene, *options):
    out = tmp_path / "cli.exr"
    cli("render", SCENES / scene, "-o", out, "--width", SIZE["width"], "--height", SIZE["height"], "--quiet", *options)
    return out


@pytest.mark.parametrize("scene,flags,kwargs", CASES, ids=[c[0] + " " + " ".join(c[1]) for c in CASES])
def test_python_render_equals_the_cli_bit_for_bit(cli, tmp_path, scene, flags, kwargs):
    expected = read_exr(cli_render(cli, tmp_path, scene, *flags))
    image = airlight.load(SCENES / scene).render(**SIZE, **kwargs)
    assert image.dtype == np.float32 and image.shape == (SIZE["height"], SIZE["width"], 3)
    assert image.mean() > 0
    assert np.array_equal(image, expected), airlight.compare(image, expected)


def test_animation_frames_equal_the_cli_in_any_order(cli, tmp_path):
    # The Cornell box's ceiling light (an area light) slides along keyframes;
    # radiosity relights for each frame.
    scene = airlight.load(SCENES / "cornell_box.toml")
    assert scene.is_animated
    frames = {k: scene.frame(k, 3).render(**SIZE, spp=1) for k in (2, 0, 1)}
    for k in (0, 1, 2):
        out = tmp_path / "f.exr"
        cli("render", SCENES / "cornell_box.toml", "-o", out, "--frames", 3, "--frame", k, "--spp", 1,
            "--width", SIZE["width"], "--height", SIZE["height"], "--quiet")
        expected = read_exr(tmp_path / f"f_{k:04}.exr")
        assert np.array_equal(frames[k], expected), (k, airlight.compare(frames[k], expected))
    assert not np.array_equal(frames[0], frames[2])
    # A still render after the frames: the lights as written again.
    still = scene.render(**SIZE, spp=1)
    assert np.array_equal(still, read_exr(cli_render(cli, tmp_path, "cornell_box.toml", "--spp", "1")))


def test_a_scene_from_dicts_renders_as_its_file():
    path = SCENES / "spheres_point_fog.toml"
    from_file = airlight.load(path).render(**SIZE)
    d = tomllib.loads(path.read_text())
    assert np.array_equal(airlight.Scene(d, base_dir=SCENES).render(**SIZE), from_file)
    assert np.array_equal(airlight.loads(path.read_text()).render(**SIZE), from_file)


def test_compare_prints_the_cli_figures(cli, tmp_path):
    a = tmp_path / "a.exr"
    b = tmp_path / "b.exr"
    cli("render", SCENES / "spheres_point_fog.toml", "-o", a, "--width", 48, "--height", 32, "--quiet")
    cli("render", SCENES / "spheres_point_fog.toml", "-o", b, "--width", 48, "--height", 32, "--quiet", "--seed", 1)
    printed = {}
    for line in cli("compare", a, b).stdout.splitlines():
        key, value = line.split(": ")
        printed[key] = tuple(map(float, value.split())) if " " in value else float(value)
    c = airlight.compare(read_exr(a), read_exr(b))
    for key in ("rmse", "rel_mse", "mae", "max", "rel_rmse"):
        assert getattr(c, key) == printed[key], key
    # The means are f32, which the CLI prints in f32's shortest form.
    for key in ("mean_a", "mean_b"):
        assert np.array_equal(np.float32(getattr(c, key)), np.float32(printed[key])), key
    assert c.as_dict()["rel_rmse"] == printed["rel_rmse"] > 0


# The EXR layers `--aov` writes, by the names render(aovs=...) gives them.
LAYERS = {
    "albedo": ["albedo.R", "albedo.G", "albedo.B"],
    "normal": ["N.X", "N.Y", "N.Z"],
    "depth": ["Z"],
    "variance": ["variance.R", "variance.G", "variance.B"],
}


@pytest.mark.parametrize("scene", ["spheres_point_fog.toml", "sdf_isometric.toml"])
def test_aovs_equal_the_layers_the_cli_writes(cli, tmp_path, scene):
    # sdf_isometric renders with `stochastic`, whose camera rays are stratified.
    cli_render(cli, tmp_path, scene, "--aov", "albedo,normal,depth,variance", "--spp", "3")
    channels = read_channels(tmp_path / "cli.exr")
    out = airlight.load(SCENES / scene).render(**SIZE, spp=3, aovs=True)
    assert np.array_equal(out["color"], np.stack([channels[c] for c in "RGB"], axis=-1))
    for name, layer in LAYERS.items():
        expected = np.stack([channels[c] for c in layer], axis=-1)
        got = out[name] if out[name].ndim == 3 else out[name][..., None]
        assert np.array_equal(got, expected), name
    assert np.isfinite(out["depth"]).any() and out["albedo"].max() > 0


def test_an_adaptive_scene_renders_as_the_cli_and_refuses_shards(cli, tmp_path):
    # `[render] adaptive = true` in the scene: the pilot and the counts are
    # the CLI's `--adaptive`, so the pixels are too.
    text = (SCENES / "compare_cornell.toml").read_text().replace("[render]\n", "[render]\nadaptive = true\n", 1)
    path = tmp_path / "adaptive.toml"
    path.write_text(text)
    out = tmp_path / "cli.exr"
    cli("render", SCENES / "compare_cornell.toml", "--adaptive", "--spp", 16, "-o", out,
        "--width", SIZE["width"], "--height", SIZE["height"], "--quiet")
    scene = airlight.load(path)
    image = scene.render(**SIZE, spp=16)
    assert np.array_equal(image, read_exr(out)), airlight.compare(image, read_exr(out))
    uniform = airlight.load(SCENES / "compare_cornell.toml").render(**SIZE, spp=16)
    assert not np.array_equal(image, uniform)
    with pytest.raises(ValueError, match="adaptive sampling renders in one go"):
        scene.render(**SIZE, spp=16, shard=(0, 2))
