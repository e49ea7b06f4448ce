"""Rendering releases the GIL, reports progress on the calling thread, and
stops on Ctrl-C (SIGINT) within a second."""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest
from conftest import SCENES

import airlight

# Many small tiles of quick samples: a render that takes seconds but whose
# tiles (16×16 pixels) take milliseconds, so a cancel is seen at once.
LONG = dict(integrator="direct", width=1024, height=1024, spp=64)


def test_other_python_threads_run_during_a_render():
    scene = airlight.load(SCENES / "four_lights.toml")
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    start = time.monotonic()
    scene.render(**dict(LONG, spp=4))
    end = time.monotonic()
    stop.set()
    t.join()
    during = [x for x in ticks if start <= x <= end]
    assert end - start > 1.0, "the render is too quick to tell"
    gaps = [b - a for a, b in zip([start, *during], [*during, end])]
    # The ticking thread never waited for the render to give the GIL back
    # (it competes for the cores with the render's threads, hence the
    # margin; a held GIL would stop it for the whole render).
    assert max(gaps) < 0.25, max(gaps)
    assert len(during) >= 20


def test_progress_is_reported_on_the_calling_thread_every_tenth_of_a_second():
    scene = airlight.load(SCENES / "four_lights.toml")
    calls = []
    caller = threading.get_ident()

    def progress(done, total):
        calls.append((time.monotonic(), done, total, threading.get_ident()))

    scene.render(progress=progress, **dict(LONG, spp=4))
    total = 1024 * 1024 * 4
    assert len(calls) >= 3
    assert all(c[2] == total and c[3] == caller for c in calls)
    assert [c[1] for c in calls] == sorted(c[1] for c in calls)
    assert calls[-1][1] == total
    # At most every 0.1 s, except the last call, which reports the end.
    assert all(b[0] - a[0] >= 0.099 for a, b in zip(calls[:-2], calls[1:-1]))


def test_a_tqdm_like_bar_gets_updates_that_add_up_to_the_total():
    class Bar:
        total = None
        n = 0

        def update(self, k):
            self.n += k

        def refresh(self):
            pass

    bar = Bar()
    airlight.load(SCENES / "four_lights.toml").render(progress=bar, width=64, height=48, spp=2)
    assert bar.total == bar.n == 64 * 48 * 2


def test_an_exception_in_the_progress_callback_stops_the_render():
    scene = airlight.load(SCENES / "four_lights.toml")

    def progress(done, total):
        raise RuntimeError("enough")

    start = time.monotonic()
    with pytest.raises(RuntimeError, match="enough"):
        scene.render(progress=progress, **LONG)
    assert time.monotonic() - start < 2
    # The scene is free again for the next render.
    assert scene.render(width=8, height=6, spp=1).shape == (6, 8, 3)


CHILD = textwrap.dedent(
    """
    import signal, sys, time, airlight
    # A Python started with SIGINT ignored (a background job of a shell
    # without job control) installs no Ctrl-C handler: it is set here,
    # or the signal would not reach the render.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    scene = airlight.load(sys.argv[1])
    started = False
    def progress(done, total):
        global started
        if not started:
            started = True
            print("rendering", flush=True)
    try:
        scene.render(progress=progress, integrator="direct", width=1024, height=1024, spp=4096)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        # The render stopped cleanly: the scene renders again.
        print("again", scene.render(width=8, height=6, spp=1).shape, flush=True)
    """
)


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
def test_sigint_stops_a_long_render_within_a_second(tmp_path):
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    command = [sys.executable, str(script), str(SCENES / "four_lights.toml")]
    with subprocess.Popen(command, stdout=subprocess.PIPE, text=True) as child:
        try:
            assert child.stdout.readline().strip() == "rendering"
            time.sleep(0.5)
            sent = time.monotonic()
            os.kill(child.pid, signal.SIGINT)
            assert child.stdout.readline().strip() == "interrupted"
            assert time.monotonic() - sent < 1.0, time.monotonic() - sent
            assert child.stdout.readline().strip() == "again (6, 8, 3)"
            assert child.wait(timeout=10) == 0
        finally:
            child.kill()
