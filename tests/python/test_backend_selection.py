"""Backend discovery and selection, the CPU fallback, and the Renderer life cycle."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import airlight


def _run_python(code: str, **env: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=60, env={**os.environ, **env})


def test_available_backends_lists_cpu_and_gl_exactly_when_gl_runs() -> None:
    backends = airlight.available_backends()
    assert "cpu" in backends
    assert set(backends) <= {"gl", "cpu"} and len(backends) == len(set(backends))
    reason = airlight.gl_unavailable_reason()
    if reason is None:
        assert backends == ["gl", "cpu"]
    else:
        assert backends == ["cpu"]
        assert isinstance(reason, str) and reason


def test_gl_renderer_reports_its_backend_when_available() -> None:
    if airlight.gl_unavailable_reason() is not None:
        pytest.skip(f"GL backend unavailable: {airlight.gl_unavailable_reason()}")
    with airlight.Renderer("gl") as r:
        assert r.backend == "gl"
    software = airlight.backend_info()["gl_software"]
    with airlight.Renderer("auto") as r:
        if software:
            assert r.backend == "cpu", "auto must pick the CPU where the only GL is a software rasteriser"
        else:
            assert r.backend == "gl", "auto must pick GL where a hardware GL renderer runs"


def test_backend_info_says_which_gl_renderer_auto_found() -> None:
    """backend_info() names the GL renderer and the choice of "auto" (issue 17): GL only on a
    hardware renderer; consistent with available_backends() and gl_unavailable_reason()."""
    info = airlight.backend_info()
    assert set(info) == {"auto", "gl_available", "gl_renderer", "gl_software", "gl_unavailable_reason"}
    assert info["gl_available"] == ("gl" in airlight.available_backends())
    assert info["gl_unavailable_reason"] == airlight.gl_unavailable_reason()
    if info["gl_available"]:
        assert isinstance(info["gl_renderer"], str) and info["gl_renderer"]
        assert info["gl_software"] == airlight._core.is_software_gl_renderer(info["gl_renderer"])
    else:
        assert info["gl_renderer"] is None and info["gl_software"] is False
    assert info["auto"] == ("gl" if info["gl_available"] and not info["gl_software"] else "cpu")
    with airlight.Renderer("auto") as r:
        assert r.backend == info["auto"]


@pytest.mark.parametrize(("name", "software"), [
    ("llvmpipe (LLVM 15.0.6, 256 bits)", True),
    ("softpipe", True),
    ("Mesa X11 swrast", True),
    ("LLVMPIPE (LLVM 17.0.6, 128 bits)", True),
    ("NVIDIA H200/PCIe/SSE2", False),
    ("AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 15.0.7, DRM 3.54, 6.5.0)", False),
    ("Mesa Intel(R) UHD Graphics 620 (KBL GT2)", False),
    ("", False),
])
def test_software_gl_renderers_are_recognised(name: str, software: bool) -> None:
    assert airlight._core.is_software_gl_renderer(name) is software


def test_auto_picks_the_cpu_on_a_software_gl_renderer_and_gl_stays_explicit(scene_factory) -> None:
    """Where GL is Mesa's llvmpipe (these machines), "auto" renders on the CPU, without a
    warning, and backend="gl" still renders on llvmpipe."""
    info = airlight.backend_info()
    if not info["gl_software"]:
        found = info["gl_renderer"] or info["gl_unavailable_reason"]
        pytest.skip(f"the GL renderer is not a software one: {found}")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with airlight.Renderer("auto") as r:
            assert r.backend == "cpu"
            auto = r.render(scene_factory(), width=16, height=12)
    np.testing.assert_array_equal(auto, airlight.render(scene_factory(), backend="cpu", width=16, height=12))
    with airlight.Renderer("gl") as r:
        assert r.backend == "gl"
        assert r.render(scene_factory(), width=16, height=12).shape == (12, 16, 3)


def test_cpu_renderer_reports_its_backend() -> None:
    with airlight.Renderer("cpu") as r:
        assert r.backend == "cpu"


_DISABLED_GL_SCRIPT = """
    import json, warnings
    import numpy as np
    import airlight
    result = {"reason": airlight.gl_unavailable_reason(), "backends": airlight.available_backends(),
              "info": airlight.backend_info()}
    try:
        airlight.Renderer("gl")
        result["gl"] = "no error"
    except Exception as e:
        result["gl"] = type(e).__name__ + ": " + str(e)
        result["is_backend_unavailable"] = isinstance(e, airlight.BackendUnavailableError)
        result["is_runtime_error"] = isinstance(e, RuntimeError)
    scene = airlight.preset("default")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        a = airlight.render(scene, backend="auto", width=32, height=24)
        b = airlight.render(scene, backend="auto", width=16, height=12)
        with airlight.Renderer("auto") as r:
            backend = r.backend
    result["warnings"] = [(w.category.__name__, str(w.message)) for w in caught]
    result["shapes"] = [list(a.shape), list(b.shape)]
    result["auto_backend"] = backend
    result["cpu_equal"] = bool(np.array_equal(a, airlight.render(scene, backend="cpu", width=32, height=24)))
    print(json.dumps(result))
"""


@pytest.fixture(scope="module")
def disabled_gl_result() -> dict:
    proc = _run_python(_DISABLED_GL_SCRIPT, AIRLIGHT_DISABLE_GL="1")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_disabled_gl_is_reported_unavailable_with_a_reason(disabled_gl_result: dict) -> None:
    assert disabled_gl_result["backends"] == ["cpu"]
    assert "AIRLIGHT_DISABLE_GL" in disabled_gl_result["reason"]
    assert disabled_gl_result["info"] == {
        "auto": "cpu", "gl_available": False, "gl_renderer": None, "gl_software": False,
        "gl_unavailable_reason": disabled_gl_result["reason"]}


def test_requesting_gl_where_unavailable_raises_backend_unavailable_error(disabled_gl_result: dict) -> None:
    assert disabled_gl_result.get("is_backend_unavailable"), f"raised {disabled_gl_result['gl']}"
    assert disabled_gl_result["is_runtime_error"], "BackendUnavailableError is documented as a RuntimeError"
    assert "AIRLIGHT_DISABLE_GL" in disabled_gl_result["gl"], "the error must say why GL is unavailable"


def test_auto_falls_back_to_cpu_with_exactly_one_runtime_warning(disabled_gl_result: dict) -> None:
    warnings_seen = disabled_gl_result["warnings"]
    assert len(warnings_seen) == 1, warnings_seen
    category, message = warnings_seen[0]
    assert category == "RuntimeWarning"
    assert "GL" in message and "cpu" in message.lower()
    assert disabled_gl_result["shapes"] == [[24, 32, 3], [12, 16, 3]]
    assert disabled_gl_result["auto_backend"] == "cpu"
    assert disabled_gl_result["cpu_equal"], "the fallback must render exactly what the CPU backend renders"


@pytest.mark.parametrize("name", ["GL", "opengl", "", "cuda", "cpu "])
def test_unknown_backend_name_raises_value_error(name: str) -> None:
    with pytest.raises(ValueError, match="backend"):
        airlight.Renderer(name)
    with pytest.raises(ValueError, match="backend"):
        airlight.render(airlight.preset("default"), backend=name, width=8, height=8)


def test_non_string_backend_raises_type_error() -> None:
    with pytest.raises(TypeError, match="backend"):
        airlight.Renderer(None)  # type: ignore[arg-type]


def test_negative_cpu_threads_raises_value_error() -> None:
    with pytest.raises(ValueError, match="cpu_threads"):
        airlight.Renderer("cpu", cpu_threads=-1)


def test_cpu_thread_count_does_not_change_the_image(scene_factory) -> None:
    scene = scene_factory(film={"width": 48, "height": 36})
    with airlight.Renderer("cpu", cpu_threads=1) as one, airlight.Renderer("cpu", cpu_threads=3) as three:
        np.testing.assert_array_equal(one.render(scene), three.render(scene))


def test_one_renderer_renders_many_scenes_and_sizes_like_fresh_renderers(backend: str, scene_factory) -> None:
    frames = [
        (scene_factory(), 40, 30),
        (scene_factory(medium=None, lights=[]), 17, 9),
        (scene_factory(surfaces=[]), 64, 48),
        (scene_factory(medium={"sigma_t": [0.01, 0.05, 0.2]}), 40, 30),
        (scene_factory(), 5, 80),
        (scene_factory(), 40, 30),
    ]
    with airlight.Renderer(backend) as reused:
        images = [reused.render(scene, width=w, height=h) for scene, w, h in frames]
    for (scene, w, h), img in zip(frames, images):
        assert img.shape == (h, w, 3)
        np.testing.assert_array_equal(img, airlight.render(scene, backend=backend, width=w, height=h))
    np.testing.assert_array_equal(images[0], images[-1])
    assert not np.array_equal(images[0], images[3])


def test_closed_renderer_refuses_to_render(backend: str, scene_factory) -> None:
    r = airlight.Renderer(backend)
    r.render(scene_factory(), width=8, height=6)
    r.close()
    with pytest.raises(RuntimeError, match="closed"):
        r.render(scene_factory(), width=8, height=6)
    r.close()  # idempotent
    with pytest.raises(RuntimeError):
        _ = r.backend


def test_context_manager_closes_the_renderer(backend: str, scene_factory) -> None:
    with airlight.Renderer(backend) as r:
        r.render(scene_factory(), width=8, height=6)
    with pytest.raises(RuntimeError):
        r.render(scene_factory(), width=8, height=6)


def test_many_renderers_can_be_created_and_closed(backend: str, scene_factory) -> None:
    scene = scene_factory()
    first = airlight.render(scene, backend=backend, width=12, height=8)
    for _ in range(5):
        with airlight.Renderer(backend) as r:
            np.testing.assert_array_equal(r.render(scene, width=12, height=8), first)


def test_two_open_renderers_interleave(backend: str, scene_factory) -> None:
    a_scene = scene_factory()
    b_scene = scene_factory(medium={"sigma_t": 0.3})
    with airlight.Renderer(backend) as a, airlight.Renderer(backend) as b:
        a1 = a.render(a_scene, width=20, height=15)
        b1 = b.render(b_scene, width=30, height=10)
        a2 = a.render(a_scene, width=20, height=15)
        b2 = b.render(b_scene, width=30, height=10)
    np.testing.assert_array_equal(a1, a2)
    np.testing.assert_array_equal(b1, b2)
