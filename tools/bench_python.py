"""The cost of rendering from Python against the CLI, on a small image.

Runs, interleaved, RUNS times each:
- cli:    `airlight render SCENE --width W --height H -o OUT.exr --quiet`, timed
          from here around the process (its start included);
- python: `airlight.save(OUT.exr, airlight.load(SCENE).render(width=W, height=H))`
          in this process: the same work, without a process start;
- render: `scene.render(width=W, height=H)` alone, the scene loaded once;
- exec:   `airlight --version`, the cost of starting the CLI at all.
Prints the medians of wall-clock time and of CPU time (user + system, of
this process's threads or of the CLI's process; less disturbed by other
work on the machine), the Python run's overhead over the CLI's, and the
load average before and after.

    python tools/bench_python.py [--bin target/release/airlight] [SCENE] [--runs 40]

Needs the airlight wheel (crates/airlight-py) installed in this Python.
"""

import argparse
import os
import resource
import statistics
import subprocess
import tempfile
import time

import airlight


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("scene", nargs="?", default="scenes/spheres_point_fog.toml")
    parser.add_argument("--bin", default="target/release/airlight")
    parser.add_argument("--width", type=int, default=64)
    parser.add_argument("--height", type=int, default=48)
    parser.add_argument("--runs", type=int, default=40)
    args = parser.parse_args()
    size = dict(width=args.width, height=args.height)
    out = os.path.join(tempfile.mkdtemp(), "out.exr")
    cli = [args.bin, "render", args.scene, "--width", str(args.width), "--height", str(args.height)]
    cli += ["-o", out, "--quiet"]

    def run_cli():
        subprocess.run(cli, check=True)

    def run_python():
        airlight.save(out, airlight.load(args.scene).render(**size))

    scene = airlight.load(args.scene)

    def run_render():
        scene.render(**size)

    def run_exec():
        subprocess.run([args.bin, "--version"], check=True, stdout=subprocess.DEVNULL)

    cases = {"cli": run_cli, "python": run_python, "render": run_render, "exec": run_exec}
    for f in cases.values():  # warm the caches
        f()
    # The pixels are the CLI's.
    expected = airlight.read_exr(out)
    run_cli()
    assert (airlight.read_exr(out) == expected).all()

    def cpu():
        own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime

    load_before = os.getloadavg()
    times = {name: [] for name in cases}
    cpu_times = {name: [] for name in cases}
    for _ in range(args.runs):
        for name, f in cases.items():
            start, start_cpu = time.perf_counter(), cpu()
            f()
            times[name].append(time.perf_counter() - start)
            cpu_times[name].append(cpu() - start_cpu)
    load_after = os.getloadavg()

    s = scene
    print(f"scene {args.scene}, {args.width}×{args.height}, {s.spp} spp, {s.integrator}, {args.runs} runs each")
    for label, table in (("wall", times), ("cpu", cpu_times)):
        med = {name: statistics.median(t) * 1e3 for name, t in table.items()}
        for name in cases:
            lo, hi = min(table[name]) * 1e3, max(table[name]) * 1e3
            print(f"{label:4s} {name:7s} median {med[name]:8.2f} ms  (min {lo:.2f}, max {hi:.2f})")
        over = med["python"] - med["cli"]
        print(f"{label:4s} python − cli: {over:+.2f} ms ({100 * over / med['cli']:+.1f}%)")
    print(f"load average before {load_before[0]:.2f}, after {load_after[0]:.2f}")


if __name__ == "__main__":
    main()
