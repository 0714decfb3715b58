"""Batch sweeps of weather and scenes on Ray (README "Datasets: batch sweeps"): a sweep
description expands into items (:func:`expand`), each rendered by one of a pool of Ray
actors that keep their :class:`airlight.Renderer` (GL context, shaders, tables) across
items, written as EXR (the chosen render outputs), PNG, masks and a metadata JSON, and
listed in ``index.jsonl``. Resumable, and a bad item is reported without stopping the
rest. ``airlight-batch SPEC --out DIR`` is the same from the shell.

    import airlight.batch
    summary = airlight.batch.run("sweep.yaml", "dataset/")
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ._items import item_dir, metadata_path, render_item
from ._spec import BatchItem, BatchSpec, SpecLike, expand, key_path, load_spec, set_path

__all__ = ["BatchItem", "BatchSpec", "BatchSummary", "expand", "key_path", "load_spec", "run", "set_path"]


@dataclass
class BatchSummary:
    """What a run did: items rendered now, skipped (already written by an earlier run),
    failed (with their reasons in ``failures``, also in ``DIR/failures.jsonl``), the wall
    time and the throughput of the rendered items."""

    total: int
    succeeded: int
    skipped: int
    failed: int
    seconds: float
    workers: int
    failures: list[dict[str, Any]] = field(default_factory=list)

    @property
    def items_per_second(self) -> float:
        return self.succeeded / self.seconds if self.seconds > 0 else 0.0

    def __str__(self) -> str:
        return (f"{self.succeeded} rendered, {self.skipped} skipped (already written), {self.failed} failed, "
                f"of {self.total}; {self.seconds:.1f} s on {self.workers} worker(s), "
                f"{self.items_per_second:.2f} items/s")


class _Worker:
    """A Ray actor: one renderer for all its items."""

    def __init__(self, backend: str, cpu_threads: int, spec: BatchSpec, out: str) -> None:
        import warnings

        from .._rendering import Renderer

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # "auto" falling back to the CPU
            self.renderer = Renderer(backend, cpu_threads=cpu_threads)
        self.spec = spec
        self.out = Path(out)

    def backend(self) -> str:
        return self.renderer.backend

    def render(self, item: BatchItem) -> dict[str, Any]:
        return render_item(self.renderer, self.spec, item, self.out)


def _ray_init(address: str | None, workers: int) -> None:
    import ray

    if ray.is_initialized():
        return
    if address is not None:
        ray.init(address=address, log_to_driver=False)
    else:
        ray.init(num_cpus=max(workers, os.cpu_count() or 1), include_dashboard=False, log_to_driver=False,
                 configure_logging=False)


def run(spec: SpecLike | BatchSpec, out: str | os.PathLike[str], *, workers: int | None = None,
        address: str | None = None, cpu_threads: int | None = None, gpus_per_worker: float | None = None,
        resume: bool = True, progress: bool = True) -> BatchSummary:
    """Renders every item of ``spec`` (:func:`load_spec`) into ``out``:

    - ``out/items/<id>.exr`` (the spec's outputs), ``<id>.png`` (the scene's display stage),
      ``<id>_mask_<name>.png`` and ``<id>.json`` (the resolved scene, parameters, package
      version, backend, timings); ``out/index.jsonl`` (one line per item done, by id),
      ``out/failures.jsonl`` (this run's failures with their reasons), ``out/spec.json``.
    - ``workers`` Ray actors (default: one per CPU core of this machine, or the cluster's
      CPUs), each with a renderer of ``cpu_threads`` threads (default: cores / workers) and
      ``gpus_per_worker`` GPUs (default: 1 where the cluster has a GPU for each worker);
      ``address``: a Ray cluster to connect to (default: a local one, started if needed).
    - ``resume``: items whose metadata already exists are skipped.
    """
    import ray

    s = spec if isinstance(spec, BatchSpec) else load_spec(spec)
    out_dir = Path(out)
    item_dir(out_dir).mkdir(parents=True, exist_ok=True)
    for stale in item_dir(out_dir).glob(".*.tmp*"):  # a killed run's unfinished file
        stale.unlink()
    items = expand(s)
    todo = [it for it in items if not (resume and metadata_path(out_dir, it.id).exists())]
    skipped = len(items) - len(todo)
    (out_dir / "spec.json").write_text(json.dumps(s.raw, indent=1, default=str))
    if workers is None:
        workers = os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")
    start = time.perf_counter()
    results: list[dict[str, Any]] = []
    if todo:
        _ray_init(address, workers)
        gpus = gpus_per_worker
        if gpus is None:
            gpus = 1.0 if ray.cluster_resources().get("GPU", 0.0) >= workers else 0.0
        threads = cpu_threads if cpu_threads is not None else max(1, (os.cpu_count() or 1) // workers)
        actor: Any = ray.remote(num_cpus=1, num_gpus=gpus)(_Worker)
        pool: list[Any] = [actor.remote(s.backend, threads, s, str(out_dir))
                           for _ in range(min(workers, len(todo)))]
        from tqdm import tqdm

        bar = tqdm(total=len(todo), disable=not progress, unit="item", desc="airlight-batch",
                   postfix={"workers": len(pool)})
        queue = list(reversed(todo))
        running: dict[Any, Any] = {}
        for w in pool:  # two items in flight per actor: one renders while the next is queued
            for _ in range(2):
                if queue:
                    running[w.render.remote(queue.pop())] = w
        while running:
            done, _ = ray.wait(list(running), num_returns=1)
            w = running.pop(done[0])
            results.append(ray.get(done[0]))
            bar.update(1)
            if queue:
                running[w.render.remote(queue.pop())] = w
        bar.close()
        for w in pool:
            ray.kill(w)
    seconds = time.perf_counter() - start
    failures = [r for r in results if "failed" in r]
    with open(out_dir / "failures.jsonl", "w") as f:
        for r in sorted(failures, key=lambda r: r["id"]):
            f.write(json.dumps(r) + "\n")
    _write_index(out_dir, items)
    return BatchSummary(total=len(items), succeeded=len(results) - len(failures), skipped=skipped,
                        failed=len(failures), seconds=seconds, workers=min(workers, max(len(todo), 1)),
                        failures=sorted(failures, key=lambda r: r["id"]))


def _write_index(out_dir: Path, items: list[BatchItem]) -> None:
    """index.jsonl: one line per item of the sweep whose metadata exists, by id."""
    tmp = out_dir / ".index.jsonl.tmp"
    with open(tmp, "w") as f:
        for it in items:
            path = metadata_path(out_dir, it.id)
            if path.exists():
                meta = json.loads(path.read_text())
                keys = ("id", "source", "camera", "parameters", "files")
                f.write(json.dumps({k: meta[k] for k in keys}) + "\n")
    os.replace(tmp, out_dir / "index.jsonl")
