"""The type stubs (airlight/__init__.pyi, shipped in the wheel) describe the
module as it is: the same names, the same render() keywords, and every public
object has a docstring for help() and editors."""

import ast
import inspect
import pathlib

import pytest

import airlight

STUB = pathlib.Path(airlight.__file__).with_name("__init__.pyi")
# render()'s control arguments; the other keywords are the keys of [render].
CONTROL = {"integrator", "threads", "shard", "progress", "aovs"}


def stub_tree():
    assert STUB.is_file(), f"the wheel ships no stubs at {STUB}"
    assert STUB.with_name("py.typed").is_file()
    return ast.parse(STUB.read_text())


def public(names):
    return {n for n in names if not n.startswith("_")}


def defined(body):
    names = set()
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets)
    return public(names)


def test_the_stubs_name_what_the_module_has():
    tree = stub_tree()
    runtime = public(dir(airlight)) - {"airlight"}  # the extension inside the package
    # Names only for type checkers (aliases, a Protocol, a TypedDict) are private.
    assert defined(tree.body) == runtime == set(airlight.__all__) - {"__version__"}


def test_the_stubs_name_what_a_scene_has():
    (scene,) = [n for n in stub_tree().body if isinstance(n, ast.ClassDef) and n.name == "Scene"]
    assert defined(scene.body) == public(dir(airlight.Scene))


def test_the_render_keywords_of_the_stubs_are_the_ones_render_takes():
    (scene,) = [n for n in stub_tree().body if isinstance(n, ast.ClassDef) and n.name == "Scene"]
    overloads = [n for n in scene.body if isinstance(n, ast.FunctionDef) and n.name == "render"]
    assert len(overloads) == 2
    for f in overloads:
        names = {a.arg for a in f.args.args[1:] + f.args.kwonlyargs}
        # An unknown keyword's message lists the [render] keys render() takes.
        with pytest.raises(TypeError) as e:
            airlight.loads("").render(no_such_option=1)
        options = set(str(e.value).split("it takes ")[1].split(", "))
        assert names == CONTROL | options


def test_every_public_object_has_a_docstring():
    missing = []
    for name in public(dir(airlight)) - {"airlight", "__version__"}:
        obj = getattr(airlight, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr in public(vars(obj)):
                if not (getattr(obj, attr).__doc__ or "").strip():
                    missing.append(f"{name}.{attr}")
    assert missing == []
