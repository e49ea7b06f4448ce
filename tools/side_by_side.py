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
render use `--pattern 'image '`). Prints each pair, then the mean of
NEW/OLD over the pairs and its range. Needs `taskset` (util-linux).
"""

import argparse
import re
import statistics
import subprocess
import sys


def figure(output: str, pattern: str) -> float:
    match = re.search(re.escape(pattern) + r"\s*([0-9]+(?:\.[0-9]+)?)", output)
    if not match:
        sys.exit(f"no figure after {pattern!r} in:\n{output}")
    return float(match.group(1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=2, help="rounds of two runs each (default 2)")
    parser.add_argument("--pattern", default="image: median", help="text before the figure to compare")
    # What follows `--` is the binaries' own.
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    options = parser.parse_args(argv[:split])
    args = argv[split + 1 :]
    if not args:
        parser.error("give the binaries' arguments after --")

    ratios = []
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
            got = {}
            for name, run in runs.items():
                output, _ = run.communicate()
                if run.returncode != 0:
                    sys.exit(f"{name} failed ({run.returncode}):\n{output}")
                got[name] = figure(output, options.pattern)
            ratios.append(got["new"] / got["old"])
            print(
                f"round {round_ + 1}, old on cpu {cpus['old']}: old {got['old']:g}, new {got['new']:g}, "
                f"new/old {ratios[-1]:.3f}",
                flush=True,
            )
    print(f"new/old: mean {statistics.mean(ratios):.3f} over {len(ratios)} pairs, {min(ratios):.3f}–{max(ratios):.3f}")


if __name__ == "__main__":
    main()
