"""A long render can be interrupted (issue 27, item 8): Ctrl-C used to wait for the whole
frame (a 16384 x 16384 film could not be stopped). Renderer.render now runs the frame on
a worker thread and checks for signals every 50 ms; SIGINT cancels the frame between
rows (CPU) or 512 x 512 tiles (GL) and raises KeyboardInterrupt, and the renderer stays
usable. The demo exits with status 130 and one line. Each case runs in a subprocess
under a timeout: a render that cannot be stopped fails the test instead of hanging."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from conftest import skip_unless_backend_available

ROOT = Path(__file__).resolve().parents[2]
# About a minute of rendering at this size on two cores: far longer than the test waits.
LONG = {"width": 6000, "height": 6000}


@pytest.mark.parametrize("backend", ["cpu", "gl"])
def test_sigint_interrupts_a_long_render_and_the_renderer_stays_usable(backend):
    skip_unless_backend_available(backend)
    script = textwrap.dedent(f"""
        import os, signal, threading, airlight
        # Python's own Ctrl-C handler, also when the test runs where SIGINT is ignored (a job
        # started in the background by a non-interactive shell inherits SIG_IGN, and Python then
        # installs none: the render would finish).
        signal.signal(signal.SIGINT, signal.default_int_handler)
        scene = airlight.load_scene("scenes/default.json")
        r = airlight.Renderer("{backend}")
        threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        try:
            r.render(scene, width={LONG["width"]}, height={LONG["height"]})
            print("finished")
        except KeyboardInterrupt:
            print("interrupted")
        print(r.render(scene, width=8, height=6).shape)
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["interrupted", "(6,", "8,", "3)"], done.stdout


def test_sigint_stops_the_demo_with_status_130(tmp_path):
    demo = Path(sys.executable).with_name("airlight-demo")
    if not demo.exists():
        pytest.skip(f"{demo} is not installed")
    args = [str(demo), "--scene", str(ROOT / "scenes" / "default.json"), "--backend", "cpu",
            "--width", str(LONG["width"]), "--height", str(LONG["height"]),
            "--out", str(tmp_path / "long.png")]
    process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)  # past the demo's start (its handler is installed first thing), well inside the render
    os.kill(process.pid, signal.SIGINT)
    try:
        _, stderr = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        process.kill()
        pytest.fail("the demo did not stop on SIGINT")
    assert process.returncode == 130
    assert stderr.strip().splitlines()[-1] == "airlight-demo: interrupted"
    assert not (tmp_path / "long.png").exists()
