"""Shared fixtures: the repository's scenes and the `airlight` binary.

The binary is $AIRLIGHT_BIN, else target/release/airlight under
$CARGO_TARGET_DIR or the repository. Tests that need it skip without it,
except under AIRLIGHT_CI=1 (as .ci/run and crates/airlight-cli/tests/python.rs
set), where every skip is a failure.
"""

import os
import pathlib
import subprocess
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).parent))

REPO = pathlib.Path(__file__).resolve().parents[3]
SCENES = REPO / "scenes"


def _binary():
    if os.environ.get("AIRLIGHT_BIN"):
        return pathlib.Path(os.environ["AIRLIGHT_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "airlight"


@pytest.fixture(scope="session")
def airlight_bin():
    path = _binary()
    if not path.is_file():
        message = f"no airlight binary at {path} (cargo build --release -p airlight-cli, or set AIRLIGHT_BIN)"
        if os.environ.get("AIRLIGHT_CI") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def cli(airlight_bin):
    """Runs `airlight ARGS...`; returns the completed process (output as text)."""

    def run(*args, cwd=REPO, check=True):
        p = subprocess.run([str(airlight_bin), *map(str, args)], cwd=cwd, capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"airlight {' '.join(map(str, args))} failed:\n{p.stderr}")
        return p

    return run


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Under AIRLIGHT_CI=1 a skipped test is reported as failed."""
    outcome = yield
    report = outcome.get_result()
    if report.skipped and os.environ.get("AIRLIGHT_CI") == "1":
        report.outcome = "failed"
        report.longrepr = f"AIRLIGHT_CI=1: skipped, which CI must not do: {report.longrepr}"
