"""The GL backend across processes and threads (issue 27, items 3 and 4): a child
forked after GL was initialised refuses GL with a clear error at once (it used
to hang forever), ``backend="auto"`` falls back to the CPU there, spawned
workers use GL normally, and one GL renderer serves any thread, one call at a
time."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import numpy as np
import pytest

import airlight
from conftest import skip_unless_backend_available

ROOT = Path(__file__).resolve().parents[2]
SMALL = {"width": 16, "height": 12}


def run_script(tmp_path: Path, body: str, timeout: float = 120.0) -> str:
    """Runs `body` as a script in a fresh interpreter (a hang fails the test by its timeout, not the
    suite); a file, so that spawned workers can import its functions."""
    script = tmp_path / "script.py"
    script.write_text("import airlight, os, sys\n" + textwrap.dedent(body))
    # Its own process group, so that a hung forked child is killed with it.
    with subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True, cwd=ROOT, start_new_session=True) as process:
        try:
            stdout, stderr = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            stdout, stderr = process.communicate()
            pytest.fail(f"hung for {timeout} s: {stdout!r} {stderr!r}")
    assert process.returncode == 0, stderr
    return stdout


def test_forked_child_refuses_gl_with_a_clear_error_instead_of_hanging(tmp_path):
    skip_unless_backend_available("gl")
    out = run_script(tmp_path, """
        scene = airlight.load_scene("scenes/default.json")
        parent = airlight.Renderer("gl")
        parent.render(scene, width=8, height=6)
        pid = os.fork()
        if pid == 0:
            for make in (lambda: airlight.Renderer("gl"), lambda: parent):
                try:
                    make().render(scene, width=8, height=6)
                    print("rendered")
                except airlight.BackendUnavailableError as e:
                    print("refused:", "forked" in str(e) and "spawn" in str(e))
            print("available:", airlight.available_backends())
            os._exit(0)
        os.waitpid(pid, 0)
        print("parent still renders:", parent.render(scene, width=8, height=6).shape)
    """, timeout=60)
    assert out.splitlines() == ["refused: True", "refused: True", "available: ['cpu']",
                                "parent still renders: (6, 8, 3)"]


def test_fork_pool_workers_render_on_the_cpu_and_spawn_workers_on_gl(tmp_path):
    """Fork workers: "auto" is the CPU and "gl" is refused; spawn workers: "auto" picks what it
    picks in a fresh process (GL on a hardware renderer, the CPU on llvmpipe: backend_info,
    issue 17) and "gl" renders. Every worker's frame matches the parent's GL frame."""
    skip_unless_backend_available("gl")
    out = run_script(tmp_path, """
        import multiprocessing as mp, warnings
        warnings.simplefilter("ignore")
        import numpy as np
        def work(seed):
            scene = airlight.load_scene("scenes/default.json")
            r = airlight.Renderer("auto")
            auto = float(r.render(scene, width=16, height=12).sum())
            try:
                gl = float(airlight.Renderer("gl").render(scene, width=16, height=12).sum())
            except airlight.BackendUnavailableError:
                gl = None
            return r.backend, auto, gl
        if __name__ == "__main__":
            scene = airlight.load_scene("scenes/default.json")
            ref = float(airlight.render(scene, backend="gl", width=16, height=12).sum())
            close = lambda s: abs(s - ref) <= 1e-3 * ref
            for method in ("fork", "spawn"):
                with mp.get_context(method).Pool(2) as pool:
                    results = pool.map(work, range(2))
                backends = sorted({b for b, _, _ in results})
                autos_close = all(close(a) for _, a, _ in results)
                gl = [g for _, _, g in results]
                gl_state = "gl refused" if all(g is None for g in gl) else all(g and close(g) for g in gl)
                print(method, backends, autos_close, gl_state)
    """, timeout=120)
    auto = airlight.backend_info()["auto"]
    assert out.splitlines() == ["fork ['cpu'] True gl refused", f"spawn ['{auto}'] True True"]


def test_a_gl_renderer_serves_other_threads_one_call_at_a_time():
    skip_unless_backend_available("gl")
    scene = airlight.load_scene(ROOT / "scenes" / "default.json")
    renderer = airlight.Renderer("gl")
    here = renderer.render(scene, **SMALL)
    results: list[np.ndarray] = []
    errors: list[BaseException] = []

    def work() -> None:
        try:
            for _ in range(3):
                results.append(renderer.render(scene, **SMALL))
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert len(results) == 12
    for image in results:
        np.testing.assert_array_equal(image, here)
    # ... and the thread that created it still can.
    np.testing.assert_array_equal(renderer.render(scene, **SMALL), here)
