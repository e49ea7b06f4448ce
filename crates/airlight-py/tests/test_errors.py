"""Bad scenes and options raise Python exceptions with the CLI's messages."""

import numpy as np
import pytest
from conftest import SCENES

import airlight

# A valid scene with one line to spoil.
GOOD = """\
[render]
width = 8
height = 6

[materials.white]
albedo = 0.8

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "white"

[[lights]]
type = "point"
position = [0, 4, -2]
intensity = 20
"""

BAD = {
    "negative_radius": GOOD.replace("radius = 1", "radius = -2"),
    "unknown_key": GOOD.replace("radius = 1", "radius = 1\nradiuss = 2"),
    "unknown_material": GOOD.replace('material = "white"', 'material = "black"'),
    "bad_integrator": GOOD.replace("height = 6", 'height = 6\nintegrator = "pathtracer"'),
    "bad_steps": GOOD.replace("height = 6", "height = 6\nsteps = 0"),
    "syntax": GOOD.replace("albedo = 0.8", "albedo = "),
    "bad_type": GOOD.replace('type = "point"', 'type = "torch"'),
    "missing_mesh": GOOD.replace('type = "sphere"', 'type = "mesh"\nfile = "nowhere.obj"')
    .replace("center = [0, 1, 0]\nradius = 1\n", ""),
}


def cli_error(cli, *args):
    p = cli(*args, check=False)
    assert p.returncode != 0
    (line,) = p.stderr.strip().splitlines()
    assert line.startswith("error: ")
    return line.removeprefix("error: ")


@pytest.mark.parametrize("name", BAD)
def test_bad_scene_files_raise_the_cli_message(cli, tmp_path, name):
    path = tmp_path / f"{name}.toml"
    path.write_text(BAD[name])
    expected = cli_error(cli, "info", path)
    with pytest.raises(airlight.SceneError) as e:
        airlight.load(path)
    assert str(e.value) == expected
    assert e.value.file == str(path)
    if e.value.line is not None:
        assert expected.startswith(f"{path}:{e.value.line}:{e.value.column}: {e.value.message}")


@pytest.mark.parametrize("name", ["negative_radius", "unknown_key", "syntax"])
def test_bad_scene_text_raises_with_line_and_column(cli, tmp_path, name):
    path = tmp_path / f"{name}.toml"
    path.write_text(BAD[name])
    expected = cli_error(cli, "info", path)
    with pytest.raises(airlight.SceneError) as e:
        airlight.loads(BAD[name])
    # The CLI's "file:L:C: message" reads "line L, column C: message".
    assert expected == f"{path}:{e.value.line}:{e.value.column}: {e.value.message}"
    assert str(e.value) == f"line {e.value.line}, column {e.value.column}: {e.value.message}"


def test_a_missing_file_raises_the_cli_message(cli, tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(airlight.SceneError) as e:
        airlight.load(path)
    assert str(e.value) == cli_error(cli, "info", path)


def test_bad_dicts_raise_the_file_message_with_the_line_as_toml():
    scene = {
        "materials": {"white": {"albedo": 0.8}},
        "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": -2, "material": "white"}],
    }
    with pytest.raises(airlight.SceneError) as e:
        airlight.Scene(scene)
    assert e.value.message == "objects[0] (sphere).radius must be a positive finite number, got -2"
    assert str(e.value).startswith(e.value.message) and "`radius = -2`" in str(e.value)
    assert "[[objects]]" in e.value.toml
    with pytest.raises(TypeError, match="objects.0..radius: a value of type object"):
        airlight.Scene({"objects": [{"radius": object()}]})
    with pytest.raises(ValueError, match="camera.fov is None"):
        airlight.Scene({"camera": {"fov": None}})


def test_hostile_arrays_and_nesting_raise_instead_of_crashing(tmp_path):
    # A 70000² image in 12 bytes (every stride 0): refused before it is
    # copied, rather than aborting the interpreter.
    pixel = np.zeros(3, np.float32)
    huge = np.lib.stride_tricks.as_strided(pixel, shape=(70000, 70000, 3), strides=(0, 0, 4))
    with pytest.raises(ValueError, match="is 70000×70000 pixels; an image has at most 65536 on a side"):
        airlight.save(str(tmp_path / "x.png"), huge)
    assert not (tmp_path / "x.png").exists()
    # Dicts nested 30,000 deep: a SceneError, not a stack overflow.
    deep = inner = {}
    for _ in range(30000):
        inner["a"] = {}
        inner = inner["a"]
    with pytest.raises(airlight.SceneError, match="nested more than 256 deep"):
        airlight.Scene({"objects": [deep]})


def test_option_errors_are_the_scene_file_messages(cli, tmp_path):
    scene = airlight.loads(GOOD)
    path = tmp_path / "steps.toml"
    path.write_text(BAD["bad_steps"])
    # The file says "render.steps must be ...", render() the same for `steps`.
    file_message = cli_error(cli, "info", path).split(": ", 1)[1]
    assert file_message == "render.steps must be an integer from 1 to 1048576, got 0"
    with pytest.raises(airlight.IntegratorError) as e:
        scene.render(steps=0)
    assert "render." + str(e.value) == file_message
    with pytest.raises(airlight.IntegratorError, match="^max_depth must be an integer from 1 to 65536, got -1$"):
        scene.render(max_depth=-1)
    with pytest.raises(airlight.IntegratorError, match="^link_threshold must be a finite number ≥ 0, got -1$"):
        scene.render(link_threshold=-1.0)
    with pytest.raises(airlight.IntegratorError, match="^unknown integrator `pathtracer`; expected one of direct"):
        scene.render("pathtracer")
    with pytest.raises(airlight.IntegratorError, match="^sampling must be uniform, equiangular or mis, got the text \"best\"$"):
        scene.render(sampling="best")
    with pytest.raises(TypeError, match="unexpected keyword argument 'step'"):
        scene.render(step=4)
    with pytest.raises(TypeError, match="steps must be an integer, got float"):
        scene.render(steps=2.5)
    with pytest.raises(TypeError, match="jitter must be True or False"):
        scene.render(jitter=1)
    with pytest.raises(ValueError, match="^spp must be an integer from 1 to 16777216, got 0$"):
        scene.render(spp=0)
    with pytest.raises(ValueError, match="^threads must be an integer from 1 to 4096, got 0$"):
        scene.render(threads=0)
    with pytest.raises(ValueError, match="at most 2 shards"):
        scene.render(spp=2, shard=(0, 3))
    # NumPy numbers are numbers.
    assert scene.render(spp=np.int64(1), steps=np.uint8(4), jitter=np.bool_(False)).shape == (6, 8, 3)


def test_an_integrator_that_cannot_render_the_scene_says_why_as_the_cli_does(cli):
    expected = cli_error(cli, "render", SCENES / "fog_lights_height.toml", "--integrator", "analytic", "-o", "x.exr")
    with pytest.raises(airlight.IntegratorError) as e:
        airlight.load(SCENES / "fog_lights_height.toml").render("analytic", width=8, height=6)
    assert str(e.value) == expected
