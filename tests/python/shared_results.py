"""Results computed once per test run, shared by the run's pytest-xdist workers.

A float64 reference or a solve that several tests (or both backends' variants of one test) compare
against is computed by the first worker that needs it and read by the others from a file (they wait
on a lock meanwhile). xdist's ``--dist loadgroup`` would keep such tests on one worker, but with
pytest 9 its group marks are not honoured (measured: a group of three split over two workers)."""

from __future__ import annotations

import fcntl
import os
import pickle
import re
import tempfile
from pathlib import Path
from typing import Any, Callable, TypeVar

T = TypeVar("T")


def _run_directory() -> Path | None:
    run = os.environ.get("PYTEST_XDIST_TESTRUNUID")  # the same in every worker of one run
    if not run:
        return None
    path = Path(tempfile.gettempdir()) / f"airlight-shared-results-{run}"
    path.mkdir(exist_ok=True)
    return path


_RESULTS: dict[str, Any] = {}


def _across_workers(key: str, compute: Callable[[], Any]) -> Any:
    directory = _run_directory()
    if directory is None:
        return compute()
    stem = directory / re.sub(r"[^A-Za-z0-9_.-]", "_", key)
    with open(f"{stem}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # one worker computes, the others wait for its file
        result_file = Path(f"{stem}.pickle")
        if result_file.exists():
            return pickle.loads(result_file.read_bytes())
        result = compute()
        partial = Path(f"{stem}.partial")
        partial.write_bytes(pickle.dumps(result))
        partial.replace(result_file)
        return result


def computed_once(key: str, compute: Callable[[], T]) -> T:
    """``compute()``, once per test run for ``key`` (which must name everything the result depends
    on): in this process from memory, across xdist workers from the run's shared directory."""
    if key not in _RESULTS:
        _RESULTS[key] = _across_workers(key, compute)
    return _RESULTS[key]
