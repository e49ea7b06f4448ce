#!/usr/bin/env python3
"""Render Airlight scenes with Mitsuba 3 and with Airlight, and compare.

    pip install mitsuba==3.9.1 numpy    # once
    apt-get install libllvm19           # for llvm_ad_rgb on Debian 12
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \
        python3 tools/mitsuba_compare.py [--spp N] [--variant V]... SCENE.toml...

For each scene it translates the TOML file into a Mitsuba 3 scene (the
subset of the schema the comparison scenes use: perspective camera, quad,
sphere, box, plane and mesh objects, diffuse materials, point, spot, quad
and sphere lights, meshes with `emission` (Mitsuba's area emitter on the
mesh, one-sided as Airlight's triangle lights), a homogeneous medium
filling space or a density grid with a grey extinction), renders it with
Mitsuba's `volpath` (or `path` in vacuum), renders it with `airlight render
--integrator path` at the same size and sample count, and prints
`airlight compare` of the two, plus the noise floors: each renderer
against itself with other seeds (`--seeds N`, 2 by default: the per-pixel
variance across N renders), from which each image's own error and the
time each renderer needs for the same error follow (error ∝ 1/√time).
A scene whose `[render] integrator` is "direct" runs Mitsuba's `direct`
(one emitter sample, no BSDF sample) and Airlight's `direct` instead.

Variants: by default `llvm_ad_rgb` (Mitsuba's fastest CPU variant:
vectorised wavefronts, JIT-compiled by LLVM; Debian 12's LLVM 15 crashes it,
LLVM 19 works) and `scalar_rgb`, each timed in the same run. In the llvm
variants `mi.render` only records the computation: the time is taken
around `mi.render`, `dr.eval` and `dr.sync_thread`, after a first render
with another seed that compiles the kernels: no scene loading, no file
writing. Airlight's time, to compare like with like, is the "image" part of
what `airlight render` reports: the samples of every pixel rendered into
the image, after the scene is loaded and its BVH built (as Mitsuba's
excludes `load_dict`), without building the integrator, the preflight
probe or writing the EXR. Airlight's whole command after loading (those
included) is printed beside it as "command". With `--repeat N` each
renderer is timed N times and the fastest is kept (Airlight's runs are
separate processes, each rendering once; Mitsuba's follow its warm-up).

Conventions matched (docs/scene-format.md): intensities in W/sr, radiance for
area lights; a pixel is the box-filtered mean; Mitsuba's max_depth counts
path segments, so it is Airlight's max_depth + 1; a quad light is a
`rectangle` whose +z normal is edge_u × edge_v; an area light's surface
reflects nothing; the spot's linear profile is Mitsuba's falloff.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def colour(v, default=0.0):
    if v is None:
        v = default
    if isinstance(v, (int, float)):
        return [float(v)] * 3
    return [float(x) for x in v]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def rotation(deg):
    """Rz·Ry·Rx for rotations in degrees about x, then y, then z."""
    import mitsuba as mi
    rx, ry, rz = deg
    return mi.ScalarTransform4f().rotate([0, 0, 1], rz) @ mi.ScalarTransform4f().rotate([0, 1, 0], ry) @ mi.ScalarTransform4f().rotate([1, 0, 0], rx)


def object_transform(o):
    import mitsuba as mi
    t = mi.ScalarTransform4f().translate(o.get("translate", [0, 0, 0]))
    s = o.get("scale", 1.0)
    s = [s] * 3 if isinstance(s, (int, float)) else s
    return t @ rotation(o.get("rotate", [0, 0, 0])) @ mi.ScalarTransform4f().scale(s)


def rectangle(corner, eu, ev):
    """A Mitsuba rectangle ([-1, 1]², normal +z) mapped onto corner + u·eu + v·ev."""
    import mitsuba as mi
    n = norm(cross(eu, ev))
    c = [corner[i] + 0.5 * (eu[i] + ev[i]) for i in range(3)]
    m = [[0.5 * eu[i], 0.5 * ev[i], n[i], c[i]] for i in range(3)] + [[0, 0, 0, 1]]
    return mi.ScalarTransform4f(m)


def translate(path, spp, sampler="independent"):
    import mitsuba as mi
    with open(path, "rb") as f:
        s = tomllib.load(f)
    r = s.get("render", {})
    cam = s.get("camera", {})
    width, height = r.get("width", 640), r.get("height", 480)
    max_depth = r.get("max_depth", 8)
    medium = s.get("medium")
    scene = {"type": "scene"}
    ext = {}
    if medium:
        kind = medium.get("type", "homogeneous")
        if kind not in ("homogeneous", "grid"):
            raise SystemExit(f"{path}: only homogeneous and grid media translate to Mitsuba here")
        sa, ss = colour(medium.get("sigma_a")), colour(medium.get("sigma_s"))
        st = [a + b for a, b in zip(sa, ss)]
        scene["fog"] = {
            "type": "homogeneous",
            "id": "fog",
            "sigma_t": {"type": "rgb", "value": st},
            "albedo": {"type": "rgb", "value": [b / t if t > 0 else 0.0 for b, t in zip(ss, st)]},
            "phase": {"type": "hg", "g": float(medium.get("g", 0.0))},
        }
        if kind == "grid":
            # Mitsuba's heterogeneous medium: one extinction (the grid times
            # `scale`), so σt must be grey; the .vol's box placed by the
            # medium's transform, as Airlight places it.
            if max(st) - min(st) > 1e-6 * max(st):
                raise SystemExit(f"{path}: a grid compares with Mitsuba only with a grey sigma_a + sigma_s")
            grid = {"type": "gridvolume", "filename": os.path.join(os.path.dirname(path), medium["file"]),
                    "use_grid_bbox": True, "to_world": object_transform(medium)}
            scene["fog"].update({"type": "heterogeneous", "sigma_t": grid,
                                 "scale": st[0] * float(medium.get("density_scale", 1.0))})
        ext = {"exterior": {"type": "ref", "id": "fog"}, "interior": {"type": "ref", "id": "fog"}}
    if r.get("integrator") == "direct":
        scene["integrator"] = {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0}
    else:
        scene["integrator"] = {"type": "volpath" if medium else "path", "max_depth": max_depth + 1}
    sensor = {
        "type": "perspective",
        "fov": float(cam.get("fov", 40.0)),
        "fov_axis": "y",
        "to_world": mi.ScalarTransform4f().look_at(
            origin=cam.get("position", [0, 2, -6]), target=cam.get("look_at", [0, 1, 0]), up=cam.get("up", [0, 1, 0])
        ),
        "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        "sampler": {"type": sampler, "sample_count": spp},
    }
    if medium:
        sensor["medium"] = {"type": "ref", "id": "fog"}
    scene["sensor"] = sensor
    mats = s.get("materials", {})

    def bsdf(name):
        m = mats[name]
        if m.get("type", "diffuse") != "diffuse":
            raise SystemExit(f"{path}: material {name}: only diffuse translates")
        return {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": colour(m.get("albedo"), 0.8)}}}

    black = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
    for i, o in enumerate(s.get("objects", [])):
        t = o["type"]
        if t == "sphere":
            shape = {"type": "sphere", "center": o["center"], "radius": o["radius"]}
        elif t == "quad":
            shape = {"type": "rectangle", "to_world": rectangle(o["corner"], o["edge_u"], o["edge_v"])}
        elif t == "box":
            lo, hi = o["min"], o["max"]
            c = [(a + b) / 2 for a, b in zip(lo, hi)]
            h = [(b - a) / 2 for a, b in zip(lo, hi)]
            local = mi.ScalarTransform4f().translate(c) @ mi.ScalarTransform4f().scale(h)
            shape = {"type": "cube", "to_world": object_transform(o) @ local}
        elif t == "plane":
            # A plane as a rectangle 2 km across.
            n = norm(o["normal"])
            a = norm(cross(n, [1, 0, 0] if abs(n[0]) < 0.9 else [0, 1, 0]))
            b = cross(n, a)
            size = 1000.0
            corner = [o["point"][k] - size * (a[k] + b[k]) for k in range(3)]
            shape = {"type": "rectangle", "to_world": rectangle(corner, [2 * size * x for x in a], [2 * size * x for x in b])}
        elif t == "mesh":
            # Flat-shaded, as Airlight shades meshes with the winding's normal.
            filename = os.path.join(os.path.dirname(os.path.abspath(path)), o["file"])
            shape = {"type": "obj", "filename": filename, "face_normals": True}
        else:
            raise SystemExit(f"{path}: object type {t} does not translate")
        if t in ("sphere",) and any(k in o for k in ("translate", "rotate", "scale")):
            shape = {"type": "sphere", "to_world": object_transform(o) @ mi.ScalarTransform4f().translate(o["center"]) @ mi.ScalarTransform4f().scale(o["radius"])}
        if "emission" in o:
            if t != "mesh":
                raise SystemExit(f"{path}: only a mesh's emission translates")
            # A light, not a reflecting surface (docs/scene-format.md).
            shape["bsdf"] = black
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": colour(o["emission"])}}
        else:
            shape["bsdf"] = bsdf(o["material"])
        shape.update(ext)
        scene[f"object{i}"] = shape
    for i, l in enumerate(s.get("lights", [])):
        t = l["type"]
        if t == "point":
            scene[f"light{i}"] = {"type": "point", "position": l["position"], "intensity": {"type": "rgb", "value": colour(l["intensity"])}}
        elif t == "spot":
            if l.get("profile", "smoothstep") != "linear":
                raise SystemExit(f"{path}: a spot light compares with Mitsuba only with profile = \"linear\"")
            target = l.get("look_at") or [l["position"][k] + l["direction"][k] for k in range(3)]
            cone = float(l.get("cone_angle", 30.0))
            scene[f"light{i}"] = {
                "type": "spot",
                "to_world": mi.ScalarTransform4f().look_at(origin=l["position"], target=target, up=[0, 1, 0] if abs(norm(sub(target, l["position"]))[1]) < 0.99 else [0, 0, 1]),
                "intensity": {"type": "rgb", "value": colour(l["intensity"])},
                "cutoff_angle": cone,
                "beam_width": float(l.get("falloff_start", cone)),
            }
        elif t == "quad":
            scene[f"light{i}"] = {
                "type": "rectangle",
                "to_world": rectangle(l["corner"], l["edge_u"], l["edge_v"]),
                "emitter": {"type": "area", "radiance": {"type": "rgb", "value": colour(l["radiance"])}},
                "bsdf": black,
                **ext,
            }
        elif t == "sphere":
            scene[f"light{i}"] = {
                "type": "sphere",
                "center": l["center"],
                "radius": l["radius"],
                "emitter": {"type": "area", "radiance": {"type": "rgb", "value": colour(l["radiance"])}},
                "bsdf": black,
                **ext,
            }
        else:
            raise SystemExit(f"{path}: light type {t} does not translate")
    return scene, width, height


def airlight(*args):
    binary = os.environ.get("AIRLIGHT", os.path.join(ROOT, "target", "release", "airlight"))
    out = subprocess.run([binary, *args], capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"airlight {' '.join(args)} failed: {out.stderr.strip()}")
    return out.stdout, out.stderr


def render_seconds(stderr):
    """The times `airlight render` reports ("rendered ... in T s (image I s,
    writing W s, setup S s)"): (I, T), the image's samples alone and the
    whole command after loading the scene."""
    for line in stderr.splitlines():
        if line.startswith("rendered ") and " in " in line:
            total = float(line.split(" in ")[1].split()[0])
            if "(image " not in line:
                raise SystemExit(f"airlight render did not report the image's time apart (an older binary?): {line}")
            return float(line.split("(image ")[1].split()[0]), total
    raise SystemExit(f"airlight render reported no time: {stderr.strip()}")


def time_mitsuba(mi, dr, scene, spp, seed):
    """Seconds for one render, waiting for the result: in the llvm variants
    `mi.render` returns at once and the work runs at `dr.eval`."""
    import time
    start = time.perf_counter()
    image = mi.render(scene, spp=spp, seed=seed)
    dr.eval(image)
    dr.sync_thread()
    return time.perf_counter() - start, image


def fmt(v):
    return "[" + ", ".join(f"{x:.5f}" for x in v) + "]"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="+")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--variant", action="append", help="Mitsuba variant, may repeat (default: llvm_ad_rgb and scalar_rgb)")
    p.add_argument(
        "--mitsuba-sampler",
        default="independent",
        help="Mitsuba's sampler: independent (default), stratified, multijitter, orthogonal or ldsampler; "
        "Airlight's path tracer stratifies its samples (Owen-scrambled Sobol') unless the scene says stratify = false",
    )
    p.add_argument(
        "--repeat",
        type=int,
        default=1,
        help="time each renderer this many times and keep the fastest (Airlight: separate runs; "
        "Mitsuba: renders after its warm-up), so that one slow run on a shared machine does not set a figure",
    )
    p.add_argument(
        "--seeds",
        type=int,
        default=2,
        help="render each renderer with this many seeds (at least 2) for its own error: the per-pixel variance "
        "across them; more seeds steady the equal-error ratio where a few pixels hold most of the error",
    )
    p.add_argument(
        "--airlight-arg",
        action="append",
        default=[],
        help="an extra argument for Airlight's render command, repeatable (e.g. --airlight-arg=--adaptive)",
    )
    p.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "airlight-mitsuba"))
    args = p.parse_args()
    if args.seeds < 2:
        p.error("--seeds must be at least 2: a renderer's own error is measured between seeds")
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    def own_error(paths):
        """An image's own relative RMSE, from renders of the same scene
        with different seeds: √(Σ per-pixel variance across them / Σ
        mean²), over pixels and channels (for two seeds, their rel_rmse
        over √2)."""
        images = np.stack([np.array(mi.Bitmap(p), dtype=np.float64)[..., :3] for p in paths])
        mean = images.mean(axis=0)
        return math.sqrt(images.var(axis=0, ddof=1).sum() / (mean**2).sum())
    variants = args.variant or ["llvm_ad_rgb", "scalar_rgb"]
    os.makedirs(args.out, exist_ok=True)
    field = lambda text, key: float([l for l in text.splitlines() if l.startswith(key + ":")][0].split()[1])
    means = lambda text, key: [float(x) for x in [l for l in text.splitlines() if l.startswith(key + ":")][0].split()[1:]]
    for path in args.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        with open(path, "rb") as f:
            integrator = tomllib.load(f).get("render", {}).get("integrator")
        integrator = "direct" if integrator == "direct" else "path"
        ours = os.path.join(args.out, f"{name}.airlight.exr")
        others = [os.path.join(args.out, f"{name}.airlight-seed{k}.exr") for k in range(1, args.seeds)]
        common = ["render", path, "--integrator", integrator, "--spp", str(args.spp), *args.airlight_arg]
        # The same seed gives the same image, so each run rewrites the same file.
        airlight_seconds, airlight_command = min(
            render_seconds(airlight(*common, "-o", ours)[1]) for _ in range(max(1, args.repeat))
        )
        for k, other in enumerate(others, start=1):
            airlight(*common, "--seed", str(k), "-o", other, "--quiet")
        e_a = own_error([ours, *others])
        print(
            f"{name}: {args.spp} spp, {integrator}; Airlight {airlight_seconds:.3f} s "
            f"(command {airlight_command:.3f} s), own error {e_a:.4f}"
        )
        for variant in variants:
            mi.set_variant(variant)
            scene_dict, _, _ = translate(path, args.spp, args.mitsuba_sampler)
            scene = mi.load_dict(scene_dict)
            time_mitsuba(mi, dr, scene, args.spp, 7)  # compiles the llvm kernels
            mitsuba_seconds, image = min(
                (time_mitsuba(mi, dr, scene, args.spp, 0) for _ in range(max(1, args.repeat))), key=lambda r: r[0]
            )
            ref = os.path.join(args.out, f"{name}.{variant}.exr")
            mi.util.write_bitmap(ref, image, write_async=False)
            # Mitsuba again with other seeds: its own noise, for equal-error times.
            ref_others = [os.path.join(args.out, f"{name}.{variant}-seed{k}.exr") for k in range(1, args.seeds)]
            for k, ref_other in enumerate(ref_others, start=1):
                mi.util.write_bitmap(ref_other, time_mitsuba(mi, dr, scene, args.spp, k)[1], write_async=False)
            vs = airlight("compare", ours, ref, "--map", os.path.join(args.out, f"{name}.{variant}.error.png"))[0]
            # Error falls as 1/√time, so equal error costs time · error².
            e_m = own_error([ref, *ref_others])
            # Some samplers round the count up (multijitter: 512 → 528), so
            # the per-sample ratio takes the count each renderer drew.
            mitsuba_spp = scene.sensors()[0].sampler().sample_count()
            per_sample = (mitsuba_seconds / mitsuba_spp) / (airlight_seconds / args.spp)
            print(f"  Mitsuba {variant} ({args.mitsuba_sampler} sampler, {mitsuba_spp} spp): {mitsuba_seconds:.3f} s, own error {e_m:.4f}; per sample Airlight is {per_sample:.2f}x as fast", end="")
            if e_a > 0:
                speedup = (mitsuba_seconds * e_m**2) / (airlight_seconds * e_a**2)
                print(f", at equal error {speedup:.2f}x", end="")
            print()
            print(f"    airlight vs mitsuba: rel_rmse {field(vs, 'rel_rmse'):.4f}  rmse {field(vs, 'rmse'):.5f}  mae {field(vs, 'mae'):.5f}")
            ma, mm = means(vs, "mean_a"), means(vs, "mean_b")
            print(f"    image means: airlight {fmt(ma)}  mitsuba {fmt(mm)}  ratio {fmt([a / b if b else float('nan') for a, b in zip(ma, mm)])}")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
