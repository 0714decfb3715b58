"""Renders in a child process, so that a crash or a hang of the renderer is caught.

:class:`Worker` starts a child with the ``spawn`` method (a fresh interpreter: GL cannot be
used in a forked child) that keeps one :class:`airlight.Renderer` per backend, and sends it
one request at a time. A request that does not answer within the timeout is a hang (the
child is killed); a child that dies is a crash (its exit status or signal is reported, with
the tail of its stderr, which goes to a log file). Either way the next request starts a new
child. ``fresh=True`` starts a new child for every request.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
import traceback
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class Outcome:
    """What one request gave.

    ``status``: ``"ok"``, ``"exception"`` (the renderer raised; ``error_type``, ``message``),
    ``"display-exception"`` (the render worked, the display stage raised),
    ``"crash"`` (the child died; ``message`` has the signal or exit status and its stderr's
    tail) or ``"hang"`` (no answer within the timeout). ``image``: the radiance (render),
    ``display``: the display stage's uint8 image when asked for.
    """

    status: str
    image: np.ndarray | None = None
    display: np.ndarray | None = None
    error_type: str = ""
    message: str = ""
    seconds: float = 0.0
    fallback_pixels: int = 0
    extra: dict[str, Any] = field(default_factory=dict)


def _child_main(conn: Connection, log_path: str) -> None:
    """The child's loop: requests in, outcomes (as plain tuples) out."""
    fd = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    import warnings

    import airlight

    warnings.simplefilter("ignore")
    renderers: dict[str, Any] = {}
    while True:
        try:
            request = conn.recv()
        except EOFError:
            return
        op = request["op"]
        start = time.perf_counter()
        try:
            if op == "render":
                backend = request["backend"]
                if backend not in renderers:
                    renderers[backend] = airlight.Renderer(backend)
                r = renderers[backend]
                image = r.render(request["scene"])
                seconds = time.perf_counter() - start
                shown = None
                if request["display"]:
                    try:
                        shown = airlight.display_scene(image, request["scene"], renderer=r)
                    except Exception as exc:  # reported as a failure of the display stage
                        conn.send(("display-exception", image, None, type(exc).__name__, str(exc), seconds,
                                   r.cpu_fallback_pixels))
                        continue
                conn.send(("ok", image, shown, "", "", seconds, r.cpu_fallback_pixels))
            elif op == "validate":
                airlight.load_scene(request["scene"])
                conn.send(("ok", None, None, "", "", time.perf_counter() - start, 0))
            else:
                raise ValueError(f"unknown request {op!r}")
        except Exception as exc:  # every exception is an outcome to report, not a worker failure
            tail = "".join(traceback.format_exception_only(type(exc), exc)).strip()
            conn.send(("exception", None, None, type(exc).__name__, str(exc) or tail,
                       time.perf_counter() - start, 0))


class Worker:
    """A child process that renders and validates scenes (see the module docstring)."""

    def __init__(self, log_dir: Path, *, timeout: float = 60.0, fresh: bool = False) -> None:
        self.log_dir = Path(log_dir)
        self.log_dir.mkdir(parents=True, exist_ok=True)
        self.timeout = timeout
        self.fresh = fresh
        self.restarts = 0
        self._ctx = multiprocessing.get_context("spawn")
        self._proc: Any = None
        self._conn: Connection | None = None
        self._log: Path | None = None

    def _start(self) -> None:
        self.restarts += 1
        self._log = self.log_dir / f"worker-{os.getpid()}-{self.restarts}.log"
        parent, child = self._ctx.Pipe()
        self._proc = self._ctx.Process(target=_child_main, args=(child, str(self._log)), daemon=True)
        self._proc.start()
        child.close()
        self._conn = parent

    def _log_tail(self, limit: int = 4000) -> str:
        if self._log is None or not self._log.exists():
            return ""
        text = self._log.read_text(errors="replace")
        return text[-limit:]

    def stop(self) -> None:
        """Ends the child (if any)."""
        if self._proc is not None:
            if self._conn is not None:
                self._conn.close()
            self._proc.join(timeout=5)
            if self._proc.is_alive():
                self._proc.kill()
                self._proc.join()
            if self._log is not None and self._log.exists() and self._log.stat().st_size == 0:
                self._log.unlink()
        self._proc = None
        self._conn = None

    def _kill(self) -> None:
        if self._proc is not None and self._proc.is_alive():
            self._proc.kill()
        if self._proc is not None:
            self._proc.join()
        self._proc = None
        self._conn = None

    def request(self, op: str, scene: Any, backend: str = "", display: bool = False,
                timeout: float | None = None) -> Outcome:
        """Sends one request and waits for its outcome (at most ``timeout`` seconds)."""
        if self._proc is None or not self._proc.is_alive():
            self._start()
        assert self._conn is not None
        limit = self.timeout if timeout is None else timeout
        start = time.perf_counter()
        try:
            self._conn.send({"op": op, "scene": scene, "backend": backend, "display": display})
            ready = self._conn.poll(limit)
            if not ready:
                self._kill()
                return Outcome("hang", message=f"no answer within {limit:g} s",
                               seconds=time.perf_counter() - start)
            status, image, shown, error_type, message, seconds, fallback = self._conn.recv()
        except (EOFError, BrokenPipeError, ConnectionResetError, OSError):
            proc = self._proc
            if proc is not None:
                proc.join(timeout=5)
            code = proc.exitcode if proc is not None else None
            if code is not None and code < 0:
                what = f"killed by signal {signal.Signals(-code).name}"
            else:
                what = f"exited with status {code}"
            self._proc = None
            self._conn = None
            tail = self._log_tail()
            return Outcome("crash", message=what + ("\n" + tail if tail else ""),
                           seconds=time.perf_counter() - start)
        if self.fresh:
            self.stop()
        return Outcome(status, image=image, display=shown, error_type=error_type, message=message,
                       seconds=seconds, fallback_pixels=fallback)

    def __enter__(self) -> Worker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
