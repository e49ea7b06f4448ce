#!/usr/bin/env python3
"""Times two builds of Airlight side by side: both run at once, each pinned
to one of the machine's first two processors, then with the processors
swapped, --rounds times. On a shared machine whose speed drifts by 20%
from minute to minute, two binaries run one after the other measure the
drift as much as the change; run at the same moment they see the same
neighbours, and the swap cancels a difference between the two
processors. Give the work one thread (`--threads 1`) so that each build
stays on its processor.

    python3 tools/side_by_side.py OLD_BINARY NEW_BINARY -- \\
        view scenes/cornell_box.toml --headless --threads 1 --frames 60 \\
        --path scenes/paths/cornell_fly.toml

The figure taken from each run is the first number after --pattern's
text in its output (by default the viewer's `image: median`; for a
render use `--pattern 'image '`); `--pattern` may be given several times,
each compared on the same runs, and `TEXT@N` takes the figure after the
Nth occurrence of TEXT. Prints each pair, then per pattern the mean and
geometric mean of NEW/OLD over the pairs and their range. Needs `taskset`
(util-linux).

    python3 tools/side_by_side.py OLD_BENCH NEW_BENCH --rounds 2 \\
        --pattern 'one ray at a time 1 thread:@1' --pattern 'one ray at a time 1 thread:@2' \\
        -- --no-reference      # bench_bvh: rays into and out of the mesh
"""

import argparse
import re
import statistics
import subprocess
import sys


def figure(output: str, pattern: str) -> float:
    text, _, nth = pattern.rpartition("@") if re.search(r"@[0-9]+$", pattern) else (pattern, "", "1")
    matches = list(re.finditer(re.escape(text) + r"\s*([0-9]+(?:\.[0-9]+)?)", output))
    match = matches[int(nth) - 1] if len(matches) >= int(nth) else None
    if not match:
        sys.exit(f"no figure after {pattern!r} in:\n{output}")
    return float(match.group(1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=2, help="rounds of two runs each (default 2)")
    parser.add_argument(
        "--pattern", action="append", help="text before the figure to compare, TEXT@N for its Nth occurrence "
        "(default 'image: median'; may be repeated)"
    )
    # What follows `--` is the binaries' own.
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    options = parser.parse_args(argv[:split])
    args = argv[split + 1 :]
    if not args:
        parser.error("give the binaries' arguments after --")
    patterns = options.pattern or ["image: median"]

    ratios = {p: [] for p in patterns}
    for round_ in range(options.rounds):
        for swap in (False, True):
            cpus = {"old": "1", "new": "0"} if swap else {"old": "0", "new": "1"}
            runs = {
                name: subprocess.Popen(
                    ["taskset", "-c", cpus[name], binary, *args],
                    stdout=subprocess.PIPE,
                    stderr=subprocess.STDOUT,
                    text=True,
                )
                for name, binary in (("old", options.old), ("new", options.new))
            }
            outputs = {}
            for name, run in runs.items():
                output, _ = run.communicate()
                if run.returncode != 0:
                    sys.exit(f"{name} failed ({run.returncode}):\n{output}")
                outputs[name] = output
            for pattern in patterns:
                old, new = (figure(outputs[name], pattern) for name in ("old", "new"))
                ratios[pattern].append(new / old)
                print(
                    f"round {round_ + 1}, old on cpu {cpus['old']}, {pattern!r}: old {old:g}, new {new:g}, "
                    f"new/old {ratios[pattern][-1]:.3f}",
                    flush=True,
                )
    for pattern, r in ratios.items():
        print(
            f"{pattern!r} new/old: mean {statistics.mean(r):.3f}, geometric mean {statistics.geometric_mean(r):.3f} "
            f"over {len(r)} pairs, {min(r):.3f}–{max(r):.3f}"
        )


if __name__ == "__main__":
    main()
