"""Throughput of batch sweeps (issue 25): the same sweep rendered by a bare
``Renderer.render`` loop in this process, by ``airlight.batch.run`` with one Ray worker,
and with two; each renderer on one CPU thread, so that two workers use the two cores.

    .venv/bin/python benchmarks/bench_batch.py [--items 16] [--width 160] [--scene foggy_street]
        [--backend cpu] [--outputs depth,transmittance,layers]

Prints items per second of each, the 2-worker / 1-worker ratio (the issue asks for >= 1.7
on this 2-core machine) and the batch layer's own cost per item against the bare loop
(Ray's scheduling, the EXR, PNG and metadata files). Ray's start-up (once per process) is
left out: the cluster is started before the timing. Absolute times on a shared machine are
noisy; run it on a quiet one.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from typing import Any

import numpy as np

import airlight
from airlight import batch


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--items", type=int, default=16)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--scene", default="foggy_street")
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--outputs", default="depth,transmittance,layers")
    args = ap.parse_args()
    scene = airlight.preset(args.scene)
    scene.setdefault("quality", {})["multiple_scattering"] = False  # one table for every item
    sigma = [float(s) for s in np.linspace(0.01, 0.08, args.items)]
    spec: dict[str, Any] = {"scenes": [scene], "vary": {"medium.sigma_t": sigma},
                            "film": {"width": args.width}, "outputs": args.outputs.split(","),
                            "backend": args.backend}
    items = batch.expand(spec)
    names = batch.load_spec(spec).outputs

    with airlight.Renderer(args.backend, cpu_threads=1) as r:
        r.render(items[0].scene, outputs=names)  # set-up and tables, as a worker's first item
        t0 = time.perf_counter()
        for it in items:
            out = r.render(it.scene, outputs=names)
        bare = time.perf_counter() - t0
        # Two of the files a batch item writes, timed alone on the last frame.
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            airlight.save_exr(f"{tmp}/x.exr", out)
            exr_s = time.perf_counter() - t0
            t0 = time.perf_counter()
            airlight.display_scene(out["radiance"], items[-1].scene, renderer=r)
            display_s = time.perf_counter() - t0

    import ray

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    rates = {}
    for workers in (1, 2):
        with tempfile.TemporaryDirectory() as out:
            summary = batch.run(spec, out, workers=workers, cpu_threads=1, progress=False)
            assert summary.failed == 0, summary.failures
            rates[workers] = summary.items_per_second
            seconds = summary.seconds
        if workers == 1:
            overhead = (seconds - bare) / args.items
    ray.shutdown()
    print(f"sweep: {args.items} items of {args.scene} at width {args.width}, backend {args.backend}, "
          f"outputs {','.join(names)}; one CPU thread per renderer")
    print(f"{'run':32} {'items/s':>8}")
    print(f"{'bare Renderer.render loop':32} {args.items / bare:8.2f}")
    print(f"{'airlight.batch, 1 worker':32} {rates[1]:8.2f}")
    print(f"{'airlight.batch, 2 workers':32} {rates[2]:8.2f}")
    print(f"2 workers / 1 worker: {rates[2] / rates[1]:.2f}; the batch layer's cost per item (1 worker "
          f"against the bare loop, a worker's start and first tables included): {1e3 * overhead:.0f} ms; "
          f"of it, writing the EXR {1e3 * exr_s:.0f} ms, "
          f"the display stage for the PNG {1e3 * display_s:.0f} ms")


if __name__ == "__main__":
    main()
