"""airlight's fuzzing harness (issue 27, README "Reliability").

Random valid scenes over the whole documented parameter space, corners included
(:mod:`.generate`), rendered on each backend in a worker process that may crash or hang
(:mod:`.worker`), checked for exceptions, non-finite or negative pixels and GL/CPU
disagreement (:mod:`.compare`); random bad inputs (:mod:`.mutate`) must be refused with a
``TypeError``/``ValueError`` naming the field. Failures are shrunk (:mod:`.shrink`) to a
minimal scene file with the command that replays it (:mod:`.harness`).

Run: ``.venv/bin/python -m tools.fuzz --scenes 200 --seed 1 --out fuzz-out`` (``--help``).
"""

from .harness import FuzzOptions, RunReport, check_scene, run, summary

__all__ = ["FuzzOptions", "RunReport", "check_scene", "run", "summary"]
