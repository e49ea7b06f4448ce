#!/usr/bin/env python3
"""Render Airlight scenes with Mitsuba 3 and with Airlight, and compare.

    pip install mitsuba            # once; the scalar_rgb variant runs on any CPU
    python3 tools/mitsuba_compare.py [--spp N] [--variant scalar_rgb] SCENE.toml...

For each scene it translates the TOML file into a Mitsuba 3 scene (the
subset of the schema the comparison scenes use: perspective camera, quad,
sphere, box and plane objects, diffuse materials, point, spot, quad and
sphere lights, a homogeneous medium filling space or a density grid with
a grey extinction), renders it with
Mitsuba's `volpath` (or `path` in vacuum), renders it with `airlight render
--integrator path` at the same size and sample count, and prints
`airlight compare` of the two, plus the noise floors: each renderer
against itself with another seed, from which each image's own error and
the time each renderer needs for the same error follow (error ∝ 1/√time).

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


def translate(path, spp):
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
    scene["integrator"] = {"type": "volpath" if medium else "path", "max_depth": max_depth + 1}
    sensor = {
        "type": "perspective",
        "fov": float(cam.get("fov", 40.0)),
        "fov_axis": "y",
        "to_world": mi.ScalarTransform4f().look_at(
            origin=cam.get("position", [0, 2, -6]), target=cam.get("look_at", [0, 1, 0]), up=cam.get("up", [0, 1, 0])
        ),
        "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": spp},
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
        else:
            raise SystemExit(f"{path}: object type {t} does not translate")
        if t in ("sphere",) and any(k in o for k in ("translate", "rotate", "scale")):
            shape = {"type": "sphere", "to_world": object_transform(o) @ mi.ScalarTransform4f().translate(o["center"]) @ mi.ScalarTransform4f().scale(o["radius"])}
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
    return out.stdout


def fmt(v):
    return "[" + ", ".join(f"{x:.5f}" for x in v) + "]"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="+")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--variant", default="scalar_rgb")
    p.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "airlight-mitsuba"))
    args = p.parse_args()
    import mitsuba as mi
    import time
    mi.set_variant(args.variant)
    os.makedirs(args.out, exist_ok=True)
    for path in args.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        scene_dict, _, _ = translate(path, args.spp)
        scene = mi.load_dict(scene_dict)
        start = time.time()
        image = mi.render(scene, spp=args.spp)
        mitsuba_seconds = time.time() - start
        ref = os.path.join(args.out, f"{name}.mitsuba.exr")
        mi.util.write_bitmap(ref, image, write_async=False)
        # Mitsuba again with another seed: its own noise, for equal-error times.
        ref_other = os.path.join(args.out, f"{name}.mitsuba-seed1.exr")
        mi.util.write_bitmap(ref_other, mi.render(scene, spp=args.spp, seed=1), write_async=False)
        ours = os.path.join(args.out, f"{name}.airlight.exr")
        other = os.path.join(args.out, f"{name}.airlight-seed1.exr")
        start = time.time()
        airlight("render", path, "--integrator", "path", "--spp", str(args.spp), "-o", ours, "--quiet")
        airlight_seconds = time.time() - start
        airlight("render", path, "--integrator", "path", "--spp", str(args.spp), "--seed", "1", "-o", other, "--quiet")
        vs = airlight("compare", ours, ref, "--map", os.path.join(args.out, f"{name}.error.png"))
        noise = airlight("compare", ours, other)
        mitsuba_noise = airlight("compare", ref, ref_other)
        field = lambda text, key: float([l for l in text.splitlines() if l.startswith(key + ":")][0].split()[1])
        print(f"{name}: {args.spp} spp; Mitsuba {args.variant} {mitsuba_seconds:.1f} s, Airlight {airlight_seconds:.1f} s")
        print(f"  airlight vs mitsuba: rel_rmse {field(vs, 'rel_rmse'):.4f}  rmse {field(vs, 'rmse'):.5f}  mae {field(vs, 'mae'):.5f}")
        print(f"  airlight vs airlight (seed 1): rel_rmse {field(noise, 'rel_rmse'):.4f}  rmse {field(noise, 'rmse'):.5f}  mae {field(noise, 'mae'):.5f}")
        print(f"  mitsuba vs mitsuba (seed 1): rel_rmse {field(mitsuba_noise, 'rel_rmse'):.4f}")
        # Each image's own error is the seed-to-seed difference over √2; error
        # falls as 1/√time, so equal error costs time · error².
        e_a, e_m = field(noise, "rel_rmse") / math.sqrt(2), field(mitsuba_noise, "rel_rmse") / math.sqrt(2)
        if e_a > 0:
            speedup = (mitsuba_seconds * e_m**2) / (airlight_seconds * e_a**2)
            print(f"  own error: airlight {e_a:.4f}, mitsuba {e_m:.4f}; Airlight faster at equal error by {speedup:.1f}x")
        means = lambda key: [float(x) for x in [l for l in vs.splitlines() if l.startswith(key + ":")][0].split()[1:]]
        ma, mm = means("mean_a"), means("mean_b")
        print(f"  image means: airlight {fmt(ma)}  mitsuba {fmt(mm)}  ratio {fmt([a / b if b else float('nan') for a, b in zip(ma, mm)])}")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
