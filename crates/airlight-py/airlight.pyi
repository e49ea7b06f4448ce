"""Airlight, a CPU renderer for participating media: scenes in, NumPy images out.

Scenes are read from scene files (:func:`load`), TOML text (:func:`loads`) or
dicts with the same keys (:class:`Scene`); the format is docs/scene-format.md.
Images are linear RGB, ``float32`` arrays of shape (height, width, 3).
"""

import os
import pathlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, Protocol, TypedDict, Union, final, overload

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "__version__",
    "Scene",
    "Comparison",
    "SceneError",
    "IntegratorError",
    "load",
    "loads",
    "from_dict",
    "compare",
    "read_exr",
    "save",
    "shard_samples",
]

_Path = Union[str, "os.PathLike[str]"]
_Image = npt.NDArray[np.float32]
_ArrayLike = npt.ArrayLike
# integrators: begin
_Integrator = Literal["direct", "raymarch", "analytic", "stochastic", "path", "radiosity", "ambient_occlusion"]
# integrators: end

class _Bar(Protocol):
    """What a progress bar must have: tqdm's ``update`` and ``total``."""

    total: Any
    def update(self, n: int) -> Any: ...

_Progress = Union[Callable[[int, int], Any], _Bar, bool, None]

_AOV = Literal["albedo", "normal", "depth", "variance"]

class _AOVs(TypedDict, total=False):
    """``render(aovs=...)``'s arrays, float32, in the order asked for after ``color``; the
    same values as the layers ``airlight render --aov`` writes."""

    color: _Image
    """The image: each pixel the mean of its samples (always there)."""
    albedo: _Image
    """The diffuse albedo of the first surface the camera rays meet, averaged over the
    render's camera rays (black for a light's own surface and where they meet nothing)."""
    normal: _Image
    """The first surface's unit normal in world space, turned toward the camera, averaged;
    zero where the rays meet nothing."""
    depth: npt.NDArray[np.float32]
    """Shape (height, width): the distance along the camera ray to the first surface, the
    mean over the samples that meet one; inf where none does."""
    variance: _Image
    """The estimated variance of each pixel's mean, per channel (inf with 1 sample)."""

class SceneError(ValueError):
    """A scene that cannot be read or built.

    ``str(e)`` is the message ``airlight`` prints without ``error:``: ``file:line:col: message``
    for a file, ``line L, column C: message`` for text, and for dicts the message with the
    offending line of the scene as TOML.
    """

    file: str | None
    line: int | None
    column: int | None
    message: str
    toml: str | None
    """For a scene from dicts: the TOML it was written as."""

class IntegratorError(ValueError):
    """An unknown integrator, an option out of bounds (the scene file's message, e.g.
    ``steps must be an integer from 1 to 1048576, got 0``), or an integrator that cannot
    render the scene (the message says why and what to use instead)."""

@final
class Comparison:
    """The figures ``airlight compare A.exr B.exr`` prints."""

    rmse: float
    """√(mean (a − b)²) over all pixels and channels."""
    rel_mse: float
    """mean (a − b)² / (b² + 0.01)."""
    mae: float
    """mean |a − b|."""
    max: float
    """max |a − b|."""
    rel_rmse: float
    """√(Σ(a − b)² / Σb²): the relative RMSE quoted in tests and benchmarks."""
    mean_a: tuple[float, float, float]
    mean_b: tuple[float, float, float]
    def as_dict(self) -> dict[str, Any]: ...

@final
class Scene:
    """A scene ready to render.

    ``Scene(d)`` builds one from dicts with the scene file's keys (``render``, ``camera``,
    ``materials``, ``objects``, ``lights``, ``medium``): the dict is written as TOML and read
    as a file is, so defaults, checks and messages are the file's. Scenes are immutable;
    ``at_time``, ``frame`` and ``with_lights`` return new ones.
    """

    def __new__(cls, scene: Mapping[str, Any], base_dir: _Path | None = None) -> Scene: ...
    @property
    def width(self) -> int:
        """Image width the scene asks for; ``render(width=...)`` overrides it."""
    @property
    def height(self) -> int: ...
    @property
    def spp(self) -> int:
        """Samples per pixel the scene asks for."""
    @property
    def seed(self) -> int: ...
    @property
    def integrator(self) -> _Integrator:
        """The integrator the scene names (``raymarch`` with a medium, else ``direct``)."""
    @property
    def time(self) -> float | None:
        """The animation time of the lights, or None for the lights as written."""
    @property
    def is_animated(self) -> bool:
        """Whether any light has keyframes."""
    @property
    def toml(self) -> str:
        """The scene as TOML: the file or text read, or what the dicts were written as."""
    @property
    def path(self) -> pathlib.Path | None:
        """The scene file read by :func:`load`, else None."""
    def at_time(self, time: float) -> Scene:
        """The scene with its keyframed lights at ``time`` in [0, 1] (held at the end keys
        outside). It shares this scene's integrator, which is told the lights moved:
        radiosity relights instead of recompiling."""
    def frame(self, k: int, n: int) -> Scene:
        """Frame ``k`` of ``n`` at time k/(n − 1), as ``airlight render --frames n --frame k``."""
    def with_lights(self, lights: Sequence[Mapping[str, Any]]) -> Scene:
        """The scene with these lights (dicts as the file's ``[[lights]]``, keyframes too),
        read again from its text; its lights are at their written pose."""
    @overload
    def render(
        self,
        integrator: _Integrator | None = None,
        *,
        threads: int | None = None,
        shard: tuple[int, int] | None = None,
        progress: _Progress = None,
        aovs: Literal[False] | None = None,
        # render-options: begin
        width: int | None = None,
        height: int | None = None,
        spp: int | None = None,
        seed: int | None = None,
        max_distance: float | None = None,
        background: float | tuple[float, float, float] | None = None,
        exposure: float | None = None,
        tonemap: Literal["clamp", "filmic"] | None = None,
        filter: Literal["box", "point"] | None = None,
        cull_lights: bool | None = None,
        adaptive: bool | None = None,
        steps: int | None = None,
        jitter: bool | None = None,
        shadows: bool | None = None,
        light_steps: int | None = None,
        light_quadrature: Literal["gauss", "uniform"] | None = None,
        sampling: Literal["uniform", "equiangular", "mis"] | None = None,
        stratify: bool | None = None,
        max_depth: int | None = None,
        reuse: bool | None = None,
        bounces: int | None = None,
        patch_size: float | None = None,
        link_threshold: float | None = None,
        ao_distance: float | None = None,
        # render-options: end
    ) -> _Image: ...
    @overload
    def render(
        self,
        integrator: _Integrator | None = None,
        *,
        threads: int | None = None,
        shard: tuple[int, int] | None = None,
        progress: _Progress = None,
        aovs: Literal[True] | str | Sequence[_AOV],
        # render-options: begin
        width: int | None = None,
        height: int | None = None,
        spp: int | None = None,
        seed: int | None = None,
        max_distance: float | None = None,
        background: float | tuple[float, float, float] | None = None,
        exposure: float | None = None,
        tonemap: Literal["clamp", "filmic"] | None = None,
        filter: Literal["box", "point"] | None = None,
        cull_lights: bool | None = None,
        adaptive: bool | None = None,
        steps: int | None = None,
        jitter: bool | None = None,
        shadows: bool | None = None,
        light_steps: int | None = None,
        light_quadrature: Literal["gauss", "uniform"] | None = None,
        sampling: Literal["uniform", "equiangular", "mis"] | None = None,
        stratify: bool | None = None,
        max_depth: int | None = None,
        reuse: bool | None = None,
        bounces: int | None = None,
        patch_size: float | None = None,
        link_threshold: float | None = None,
        ao_distance: float | None = None,
        # render-options: end
    ) -> _AOVs:
        """Renders the scene: linear RGB, float32, shape (height, width, 3).

        ``integrator`` and the other keywords of the scene file's ``[render]`` table (film
        settings and integrator options, by their scene-file names) override the scene's,
        checked as the file checks them: a value of the wrong kind raises ``TypeError``, an
        integrator option out of bounds ``IntegratorError``, a film setting ``ValueError``;
        None gives the option's default. ``threads`` defaults to every core; the image does
        not depend on it. ``shard=(k, n)`` renders only the k-th of n ranges of each pixel's
        samples (:func:`shard_samples`) and returns their mean. ``progress`` is a callable
        ``f(done, total)`` (pixel samples), a tqdm bar, or True for a new tqdm bar; it is called
        on this thread at most every 0.1 s. The GIL is released while rendering; Ctrl-C stops
        the render and raises KeyboardInterrupt.

        ``aovs`` (True for all, or names: a list, or a comma-separated string) returns a dict
        of arrays instead, ``color`` first, then the AOVs asked for: ``albedo``, ``normal``,
        ``depth`` and ``variance`` (see :class:`_AOVs`); not with ``shard``.

        As ``airlight render`` does, an image too large for the memory left (or for
        ``AIRLIGHT_MEMORY_LIMIT``) raises ``MemoryError`` before anything is allocated, and a
        scene that can only render black gives a ``UserWarning`` saying why.
        """

def load(path: _Path) -> Scene:
    """Reads a scene file, or a ``.gltf``/``.glb`` file as the scene of one ``[[include]]`` of
    it, as ``airlight render`` does; a bad one raises ``SceneError`` with the CLI's message
    (``file:line:col: message``). Meshes are found in the file's folder, then in
    the folders of ``AIRLIGHT_ASSET_PATH``."""

def loads(text: str, base_dir: _Path | None = None) -> Scene:
    """Reads a scene from TOML text; meshes are found in ``base_dir`` (default: the current
    folder), then in the folders of ``AIRLIGHT_ASSET_PATH``."""

def from_dict(scene: Mapping[str, Any], base_dir: _Path | None = None) -> Scene:
    """The same as ``Scene(scene, base_dir)``."""

def compare(image: _ArrayLike, reference: _ArrayLike) -> Comparison:
    """``image`` against ``reference`` (shape (H, W, 3)): the figures ``airlight compare``
    prints."""

def read_exr(path: _Path) -> _Image:
    """An EXR's RGB channels, float32 (H, W, 3)."""

def save(
    path: _Path,
    image: _ArrayLike,
    exposure: float = 0.0,
    tonemap: Literal["clamp", "filmic"] = "clamp",
) -> None:
    """Writes ``.exr`` (linear float) or ``.png`` (8-bit sRGB after ``exposure`` stops and the
    tone curve), as ``airlight render -o`` does."""

def shard_samples(spp: int, k: int, n: int) -> tuple[int, int]:
    """The sample numbers (start, stop) that ``render(shard=(k, n))`` renders of ``spp``:
    shards combine as Σ (stop − start)·image / spp."""
