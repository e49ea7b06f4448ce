"""The docs' example script runs and writes its figure (at a small size)."""

import subprocess
import sys

from conftest import REPO


def test_the_sigma_s_sweep_example_runs(tmp_path):
    out = tmp_path / "sweep.png"
    script = REPO / "docs/examples/sigma_s_sweep.py"
    p = subprocess.run(
        [sys.executable, str(script), "--width", "16", "--height", "12", "--spp", "2", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stderr
    rows = [line.split() for line in p.stdout.splitlines()[1:11]]
    # Ten σs values from 0, each with two means and an error.
    assert [float(r[0]) for r in rows][:2] == [0.0, 0.05] and len(rows) == 10
    assert all(float(r[1]) > 0 and float(r[2]) > 0 for r in rows)
    assert out.read_bytes()[:4] == b"\x89PNG"
