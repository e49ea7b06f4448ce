"""The Python API: arrays, options, shards, AOVs, animation, lights, files."""

import tomllib

import numpy as np
import pytest
from conftest import SCENES
from exr import read_exr

import airlight

SMALL = dict(width=24, height=16)


@pytest.fixture(scope="module")
def fog():
    return airlight.load(SCENES / "spheres_point_fog.toml")


def test_scene_properties(fog):
    assert (fog.width, fog.height, fog.integrator) == (640, 480, "raymarch")
    assert fog.time is None and not fog.is_animated
    assert "[render]" in fog.toml
    assert repr(fog).startswith("<airlight.Scene 640×480")


def test_render_returns_a_float32_array_that_owns_its_buffer(fog):
    image = fog.render(**SMALL, spp=2)
    assert image.dtype == np.float32 and image.shape == (16, 24, 3)
    assert image.flags.c_contiguous and image.flags.writeable
    # NumPy took the render's buffer over: the array is a view of it, not a copy.
    assert not image.flags.owndata and image.base is not None


def test_threads_do_not_change_the_image(fog):
    assert np.array_equal(fog.render(**SMALL, threads=1), fog.render(**SMALL, threads=3))


def test_options_change_the_image(fog):
    a = fog.render(**SMALL, steps=4, jitter=False)
    b = fog.render(**SMALL, steps=64, jitter=False)
    assert not np.array_equal(a, b)
    assert np.array_equal(a, fog.render(**SMALL, steps=4, jitter=False))
    assert not np.array_equal(fog.render(**SMALL, seed=1), fog.render(**SMALL, seed=2))


def test_shards_are_means_that_combine_into_the_whole_render(fog):
    whole = fog.render(**SMALL, spp=10)
    parts = []
    for k in range(3):
        start, stop = airlight.shard_samples(10, k, 3)
        parts.append((stop - start) * fog.render(**SMALL, spp=10, shard=(k, 3)).astype(np.float64))
    assert [airlight.shard_samples(10, k, 3) for k in range(3)] == [(0, 4), (4, 7), (7, 10)]
    np.testing.assert_allclose(sum(parts) / 10, whole, rtol=1e-5, atol=1e-7)


def test_aovs_give_named_arrays_beside_the_color(fog):
    out = fog.render(**SMALL, spp=4, aovs=True)
    assert list(out) == ["color", "albedo", "normal", "depth", "variance"]
    assert np.array_equal(out["color"], fog.render(**SMALL, spp=4))
    assert all(a.dtype == np.float32 for a in out.values())
    assert out["variance"].shape == (16, 24, 3) and (out["variance"] >= 0).all()
    assert out["variance"].max() > 0
    assert out["depth"].shape == (16, 24) and out["albedo"].shape == out["normal"].shape == (16, 24, 3)
    # Where the camera sees a surface, its normal is a unit vector (or the
    # mean of a few), and its distance finite.
    hit = np.isfinite(out["depth"])
    assert 0 < hit.sum() < hit.size
    lengths = np.linalg.norm(out["normal"][hit], axis=-1)
    assert (lengths > 0).all() and (lengths < 1 + 1e-5).all()
    assert (out["normal"][~hit] == 0).all()
    # Only what is asked for, in the order asked.
    some = fog.render(**SMALL, spp=4, aovs="depth, albedo")
    assert list(some) == ["color", "depth", "albedo"]
    assert np.array_equal(some["depth"], out["depth"])
    assert list(fog.render(**SMALL, aovs=["normal"])) == ["color", "normal"]
    with pytest.raises(
        ValueError, match="^aovs: unknown AOV `colour`; known: albedo, normal, depth, variance, inscatter$"
    ):
        fog.render(**SMALL, aovs="colour")
    with pytest.raises(ValueError, match="^aovs: inscatter is not computed from Python yet"):
        fog.render(**SMALL, aovs="depth,inscatter")
    with pytest.raises(ValueError, match="without a shard"):
        fog.render(**SMALL, aovs=True, shard=(0, 2))


def test_at_time_moves_keyframed_lights_and_keeps_the_scene(tmp_path):
    box = airlight.load(SCENES / "cornell_box.toml")
    a, b = box.at_time(0.0), box.at_time(1.0)
    assert (a.time, b.time, box.time) == (0.0, 1.0, None)
    ia, ib = a.render("direct", **SMALL, spp=1), b.render("direct", **SMALL, spp=1)
    assert not np.array_equal(ia, ib)
    assert np.array_equal(box.frame(2, 3).render("direct", **SMALL, spp=1), ib)
    # A scene without keyframes is the same at every time.
    fog = airlight.load(SCENES / "spheres_point_fog.toml")
    assert np.array_equal(fog.at_time(0.7).render(**SMALL), fog.render(**SMALL))
    with pytest.raises(ValueError, match="frames 0 to 2"):
        box.frame(3, 3)
    with pytest.raises(ValueError, match="finite"):
        box.at_time(float("nan"))


def test_with_lights_replaces_the_lights():
    path = SCENES / "spheres_point_fog.toml"
    scene = airlight.load(path)
    lights = tomllib.loads(path.read_text())["lights"]
    same = scene.with_lights(lights)
    assert np.array_equal(same.render(**SMALL), scene.render(**SMALL))
    brighter = [dict(light, intensity=4 * np.asarray(light["intensity"])) for light in lights]
    image = scene.with_lights(brighter).render(**SMALL)
    # Light is linear in the intensity: four times as bright, to rounding.
    np.testing.assert_allclose(image, 4 * scene.render(**SMALL), rtol=1e-4, atol=1e-6)
    with pytest.raises(airlight.SceneError, match=r"lights\[0\]"):
        scene.with_lights([{"type": "point", "position": [0, 1, 0], "intensity": -1}])
    with pytest.warns(UserWarning, match="no lights"):
        assert scene.with_lights([]).render(**SMALL, integrator="direct").max() == 0


def test_save_and_read_exr_round_trip(tmp_path, fog):
    image = fog.render(**SMALL)
    airlight.save(tmp_path / "a.exr", image)
    assert np.array_equal(airlight.read_exr(tmp_path / "a.exr"), image)
    assert np.array_equal(read_exr(tmp_path / "a.exr"), image)
    airlight.save(tmp_path / "a.png", image, exposure=1.0, tonemap="filmic")
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="tonemap|tone"):
        airlight.save(tmp_path / "b.png", image, tonemap="reinhard")
    with pytest.raises(ValueError, match=r"shape \(height, width, 3\)"):
        airlight.save(tmp_path / "b.exr", image[..., 0])


def test_compare_takes_any_float_arrays():
    a = np.ones((2, 3, 3), dtype=np.float64)
    b = np.full((2, 3, 3), 0.5, dtype=np.float32)
    c = airlight.compare(a, b)
    assert (c.rmse, c.mae, c.max) == (0.5, 0.5, 0.5)
    assert c.rel_rmse == pytest.approx(1.0)
    with pytest.raises(ValueError, match="differ in size: 3×2 and 2×3"):
        airlight.compare(a, np.ones((3, 2, 3)))


def test_compare_refuses_pixels_that_are_not_numbers_as_the_cli_does():
    a = np.ones((2, 3, 3), dtype=np.float32)
    b = a.copy()
    b[1, 2] = [np.nan, 0, np.inf]
    b[0, 1, 0] = np.nan
    with pytest.raises(ValueError, match=r"^reference has 2 pixels that are not finite .* first at \(x 1, y 0\): NaN 1 1"):
        airlight.compare(a, b)


def test_a_scene_file_knows_its_path_and_text(fog):
    assert fog.path == SCENES / "spheres_point_fog.toml"
    assert fog.toml == (SCENES / "spheres_point_fog.toml").read_text()
    assert airlight.loads(fog.toml).path is None


def test_progress_true_shows_a_tqdm_bar(fog, capsys):
    fog.render(**SMALL, spp=2, progress=True)
    err = capsys.readouterr().err
    # tqdm's last line: the whole count, with the label render() gives it.
    assert "raymarch 24×16 2 spp" in err and "100%" in err


def test_a_scene_that_can_only_be_black_is_warned_of_as_the_cli_does(cli, tmp_path):
    scene = {
        "render": {"width": 8, "height": 6},
        "materials": {"white": {"albedo": 0.8}},
        "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "white"}],
    }
    path = tmp_path / "dark.toml"
    path.write_text(airlight.Scene(scene).toml)
    warning = cli("render", path, "-o", tmp_path / "dark.png", "--quiet").stderr.strip()
    assert warning.startswith("warning: the scene has no lights")
    with pytest.warns(UserWarning) as caught:
        image = airlight.Scene(scene).render()
    assert [str(w.message) for w in caught] == [warning.removeprefix("warning: ")]
    assert image.max() == 0


def test_a_render_too_large_for_memory_is_refused_with_the_cli_message(cli, monkeypatch, tmp_path):
    monkeypatch.setenv("AIRLIGHT_MEMORY_LIMIT", "1M")
    p = cli("render", SCENES / "spheres_point_fog.toml", "-o", tmp_path / "x.png", check=False)
    assert p.returncode != 0
    expected = p.stderr.strip().removeprefix("error: ")
    assert expected.endswith(": make the image smaller (--width, --height)")
    with pytest.raises(MemoryError) as e:
        airlight.load(SCENES / "spheres_point_fog.toml").render()
    assert str(e.value) == expected.replace("(--width, --height)", "(width=, height=)")
    # A smaller image fits.
    assert airlight.load(SCENES / "spheres_point_fog.toml").render(**SMALL).shape == (16, 24, 3)


def test_a_gltf_file_loads_as_the_scene_of_one_include(cli, tmp_path):
    path = SCENES / "models/lamp_room.gltf"
    scene = airlight.load(path)
    assert scene.toml == '[[include]]\nfile = "lamp_room.gltf"\n' and scene.path == path
    out = tmp_path / "cli.exr"
    cli("render", path, "-o", out, "--width", 24, "--height", 16, "--quiet")
    assert np.array_equal(scene.render(width=24, height=16), read_exr(out))
    # Its text reads again, beside the file: a light added to the glTF's own.
    lit = scene.with_lights([{"type": "point", "position": [0, 1, 0], "intensity": 5}])
    assert lit.render(width=24, height=16).sum() > scene.render(width=24, height=16).sum()
