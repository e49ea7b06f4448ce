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
    assert [airlight.shard_samples(10, k, 3) for k in range(3)] == [(0, 3), (3, 6), (6, 10)]
    np.testing.assert_allclose(sum(parts) / 10, whole, rtol=1e-5, atol=1e-7)


def test_aovs_give_the_color_and_its_variance(fog):
    out = fog.render(**SMALL, spp=4, aovs=True)
    assert set(out) == {"color", "variance"}
    assert np.array_equal(out["color"], fog.render(**SMALL, spp=4))
    assert out["variance"].shape == (16, 24, 3) and (out["variance"] >= 0).all()
    assert out["variance"].max() > 0


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
