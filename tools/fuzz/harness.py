"""The fuzzing run: random valid scenes rendered on each backend in a worker process,
random bad inputs validated there, failures shrunk to minimal reproducers.

A valid scene's problems (:class:`Problem`): ``invalid`` (the generator made a scene that
``load_scene`` refuses: a generator bug), ``crash``, ``hang``, ``exception`` (the render
raised), ``display-exception`` (the display stage raised on the rendered image), ``shape``,
``nonfinite``, ``negative`` (pixels) and ``disagreement`` (GL against CPU,
:mod:`tools.fuzz.compare`). Each distinct problem (kind, backend, exception type) is shrunk
once (:mod:`tools.fuzz.shrink`) and written to ``<out>/findings/<id>.json`` (the minimal
scene, a plain scene file) with its original scene and the one-line command that replays
it; ``<out>/findings.md`` lists them and ``<out>/report.json`` has the run's figures.

With ``demo=PATH`` the scenes go through that ``airlight-demo`` binary instead (its CPU
backend, a new process per scene): the sanitizer run of README "Reliability".
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

import airlight

from . import compare
from .generate import GeneratorConfig, random_scene, scene_rng
from .mutate import Mutation, format_path, judge, mutate
from .shrink import shrink
from .worker import Outcome, Worker

Scene = dict[str, Any]
SANITIZER_MARKS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:",
                   "SUMMARY: UndefinedBehavior")


@dataclass
class Problem:
    """One thing wrong with one scene on one backend (``"gl+cpu"`` for a disagreement)."""

    kind: str
    backend: str
    detail: str
    error_type: str = ""

    def signature(self) -> tuple[str, str, str]:
        """What makes two problems "the same" for shrinking and counting."""
        return (self.kind, self.backend, self.error_type)


@dataclass
class Finding:
    """A distinct problem with its minimal reproducer."""

    id: str
    kind: str
    backend: str
    detail: str
    occurrences: int
    first_scene_index: int
    scene_file: str
    original_file: str
    command: str
    shrink_attempts: int = 0
    minimal_detail: str = ""
    signature: list[str] = field(default_factory=list)
    features: list[str] = field(default_factory=list)


@dataclass
class FuzzOptions:
    """A run's settings (the CLI's options, ``python -m tools.fuzz --help``)."""

    scenes: int = 100
    seed: int = 0
    backends: tuple[str, ...] = ("gl", "cpu")
    timeout: float = 180.0
    out: Path = Path("fuzz-out")
    bad_inputs: int = 0
    display: bool = True
    shrink_seconds: float = 120.0
    generator: GeneratorConfig = field(default_factory=GeneratorConfig)
    demo: str | None = None
    fresh: bool = False
    progress: bool = True
    tolerance: float = compare.TOLERANCE
    deadline: float | None = None  # time.monotonic() after which no new valid scene is started
    bad_input_grace: float = 120.0  # seconds after the deadline the bad inputs may still take


@dataclass
class RunReport:
    """The figures of a run."""

    scenes: int = 0
    backends: tuple[str, ...] = ()
    renders: int = 0
    bad_inputs: int = 0
    bad_inputs_accepted: int = 0
    seconds: float = 0.0
    problems: dict[str, int] = field(default_factory=dict)
    findings: list[Finding] = field(default_factory=list)
    max_disagreement: float = 0.0
    cpu_fallback_frames: int = 0
    worker_restarts: int = 0

    def ok(self) -> bool:
        """True when the run found nothing."""
        return not self.findings


class Progress:
    """A one-line progress bar on stderr (when stderr is not a terminal: a line per 5 %, and at
    least one a minute)."""

    def __init__(self, total: int, label: str, enabled: bool = True) -> None:
        self.total = max(total, 1)
        self.label = label
        self.enabled = enabled
        self.start = time.monotonic()
        self.tty = sys.stderr.isatty()
        self._last_step = -1
        self._next = 0.0

    def update(self, done: int, note: str = "") -> None:
        """Shows ``done`` of the total, with the rate, the time left and ``note``."""
        if not self.enabled:
            return
        elapsed = time.monotonic() - self.start
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = (self.total - done) / rate if rate > 0 else math.inf
        width = 30
        filled = int(width * done / self.total)
        bar = "#" * filled + "." * (width - filled)
        eta_text = f"{eta:4.0f} s left" if math.isfinite(eta) else "   ? s left"
        line = f"{self.label} [{bar}] {done}/{self.total} {rate:5.2f}/s {eta_text} {note}"
        if self.tty:
            sys.stderr.write("\r" + line[:150].ljust(150))
            sys.stderr.flush()
        elif (done * 20 // self.total != self._last_step or done == self.total
              or time.monotonic() > self._next):
            self._last_step = done * 20 // self.total
            self._next = time.monotonic() + 60.0
            sys.stderr.write(line + "\n")
            sys.stderr.flush()

    def message(self, text: str) -> None:
        """A line of its own above the bar."""
        if self.enabled:
            sys.stderr.write(("\r" + " " * 150 + "\r" if self.tty else "") + text + "\n")

    def close(self) -> None:
        """Ends the bar's line."""
        if self.enabled and self.tty:
            sys.stderr.write("\n")


# --- rendering and checking ----------------------------------------------------------


def _demo_render(demo: str, scene: Scene, timeout: float, out_png: bool) -> Outcome:
    """Renders ``scene`` with the demo binary (CPU backend) in a new process."""
    with tempfile.TemporaryDirectory(prefix="airlight-fuzz-") as tmp:
        scene_file = Path(tmp) / "scene.json"
        scene_file.write_text(json.dumps(scene))
        out = Path(tmp) / ("out.png" if out_png else "out.pfm")
        start = time.perf_counter()
        try:
            run = subprocess.run([demo, "--scene", str(scene_file), "--out", str(out), "--backend", "cpu"],
                                 capture_output=True, text=True, timeout=timeout, errors="replace")
        except subprocess.TimeoutExpired:
            return Outcome("hang", message=f"no exit within {timeout:g} s",
                           seconds=time.perf_counter() - start)
        seconds = time.perf_counter() - start
        if any(mark in run.stderr for mark in SANITIZER_MARKS):
            return Outcome("sanitizer", message=run.stderr[-6000:], seconds=seconds)
        if run.returncode < 0:
            return Outcome("crash", message=f"killed by signal {-run.returncode}\n{run.stderr[-4000:]}",
                           seconds=seconds)
        if run.returncode != 0:
            return Outcome("exception", error_type=f"exit {run.returncode}",
                           message=run.stderr.strip()[-2000:],
                           seconds=seconds)
        image = None if out_png else airlight.load_pfm(out)
        return Outcome("ok", image=image, seconds=seconds)


def render_outcome(worker: Worker | None, scene: Scene, backend: str, options: FuzzOptions) -> Outcome:
    """One render of ``scene`` on ``backend`` ("demo" runs the demo binary)."""
    if backend == "demo":
        assert options.demo is not None
        first = _demo_render(options.demo, scene, options.timeout, out_png=False)
        if first.status == "ok" and options.display and "display" in scene:
            shown = _demo_render(options.demo, scene, options.timeout, out_png=True)
            if shown.status != "ok":
                shown.status = "display-exception" if shown.status == "exception" else shown.status
                return shown
        return first
    assert worker is not None
    return worker.request("render", scene, backend, display=options.display)


def check_scene(worker: Worker | None, scene: Scene, backends: tuple[str, ...], options: FuzzOptions,
                report: RunReport | None = None) -> list[Problem]:
    """Everything wrong with one valid scene on ``backends`` (empty: nothing)."""
    try:
        loaded = airlight.load_scene(scene)
    except (TypeError, ValueError) as exc:
        return [Problem("invalid", "-", f"load_scene refused a generated scene: {exc}", type(exc).__name__)]
    width, height = loaded["film"]["width"], loaded["film"]["height"]
    problems: list[Problem] = []
    images: dict[str, np.ndarray] = {}
    for backend in backends:
        outcome = render_outcome(worker, scene, backend, options)
        if report is not None:
            report.renders += 1
            report.cpu_fallback_frames += outcome.fallback_pixels > 0
        if outcome.status in ("crash", "hang", "sanitizer"):
            problems.append(Problem(outcome.status, backend, outcome.message))
            continue
        if outcome.status == "exception":
            problems.append(Problem("exception", backend, f"{outcome.error_type}: {outcome.message}",
                                    outcome.error_type))
            continue
        if outcome.status == "display-exception":
            problems.append(Problem("display-exception", backend, f"{outcome.error_type}: {outcome.message}",
                                    outcome.error_type))
        if outcome.image is None:
            continue
        image_problems = compare.image_problems(outcome.image, width, height)
        problems.extend(Problem(kind, backend, detail) for kind, detail in image_problems)
        if outcome.display is not None and (outcome.display.shape != (height, width, 3)
                                            or outcome.display.dtype != np.uint8):
            problems.append(Problem("display-shape", backend,
                                    f"display gave {outcome.display.dtype} {outcome.display.shape}"))
        if not image_problems:
            images[backend] = outcome.image
    if "gl" in images and "cpu" in images:
        d = compare.disagreement(images["gl"], images["cpu"], options.tolerance)
        if report is not None:
            report.max_disagreement = max(report.max_disagreement, d.max_error)
        if d.disagree:
            problems.append(Problem("disagreement", "gl+cpu", d.describe()))
    return problems


# --- findings ------------------------------------------------------------------------


def features(scene: Any) -> set[str]:
    """What a scene is made of, coarsely: its top-level keys (not null), light and surface
    types, the medium's phase type, quality keys, sky model and atmosphere species."""
    out: set[str] = set()
    if not isinstance(scene, dict):
        return out
    for key, value in scene.items():
        if value is None:
            continue
        out.add(str(key))
        if key in ("lights", "surfaces") and isinstance(value, list):
            out.update(f"{key}:{x.get('type')}" for x in value if isinstance(x, dict))
        elif isinstance(value, dict) and key in ("quality", "atmosphere", "display"):
            out.update(f"{key}.{k}" for k, v in value.items() if v is not None)
        elif key == "medium" and isinstance(value, dict) and isinstance(value.get("phase"), dict):
            out.add(f"phase:{value['phase'].get('type')}")
        elif key == "sky" and isinstance(value, dict):
            out.add(f"sky:{value.get('model')}")
    return out


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:40]


def replay_command(path: Path, backends: tuple[str, ...], demo: str | None = None) -> str:
    """The one-line command that replays a reproducer file."""
    extra = f" --demo {demo}" if demo else ""
    return f".venv/bin/python -m tools.fuzz --replay {path} --backends {','.join(backends)}{extra}"


class Recorder:
    """Writes findings (reproducers, findings.md) into ``<out>``."""

    def __init__(self, out: Path) -> None:
        self.out = out
        self.dir = out / "findings"
        self.dir.mkdir(parents=True, exist_ok=True)
        self.findings: list[Finding] = []

    def seen(self, problem: Problem, scene: Any = None) -> Finding | None:
        """The finding already recorded for this problem: the same signature and, for a valid
        scene, a minimal reproducer whose features (:func:`features`) the scene all has (a scene
        of other features with the same kind of problem may be another bug: it is shrunk anew)."""
        for finding in self.findings:
            if finding.signature != list(problem.signature()):
                continue
            if scene is None or set(finding.features) <= features(scene):
                return finding
        return None

    def add(self, problem: Problem, index: int, original: Any, minimal: Any, attempts: int,
            minimal_detail: str, backends: tuple[str, ...], demo: str | None, bad_input: bool) -> Finding:
        """Records a new finding and writes its files."""
        n = len(self.findings) + 1
        fid = f"{n:03d}-{problem.kind}-{_slug(problem.backend)}" + (f"-{_slug(problem.error_type)}"
                                                                      if problem.error_type else "")
        scene_file = self.dir / f"{fid}.json"
        original_file = self.dir / f"{fid}.original.json"
        if bad_input:
            command = _write_bad_input(scene_file, original_file, minimal, original)
        else:
            scene_file.write_text(json.dumps(minimal, indent=1) + "\n")
            original_file.write_text(json.dumps(original, indent=1) + "\n")
            command = replay_command(scene_file, backends, demo)
        finding = Finding(fid, problem.kind, problem.backend, problem.detail[:2000], 1, index,
                          str(scene_file), str(original_file), command, attempts, minimal_detail[:2000],
                          list(problem.signature()),
                          sorted(features(minimal)) if not bad_input else [])
        self.findings.append(finding)
        self.write_index()
        return finding

    def write_index(self) -> None:
        """(Re)writes ``findings.md``."""
        lines = ["# Fuzz findings", ""]
        if not self.findings:
            lines.append("None.")
        for f in self.findings:
            lines += [f"## {f.id}", "", f"- kind: {f.kind}, backend: {f.backend}, seen {f.occurrences} times "
                      f"(first: scene {f.first_scene_index})",
                      f"- minimal reproducer: `{f.scene_file}` (original: `{f.original_file}`, "
                      f"{f.shrink_attempts} shrinking tries)",
                      f"- replay: `{f.command}`", "", "```", (f.minimal_detail or f.detail).strip()[:1500],
                      "```", ""]
        (self.out / "findings.md").write_text("\n".join(lines))


def _write_bad_input(scene_file: Path, original_file: Path, minimal: Mutation, original: Any) -> str:
    """Writes a bad-input reproducer: JSON when the input is JSON, else a Python literal."""
    payload = {"mutated_path": format_path(minimal.path), "what": minimal.what, "scene": minimal.scene}
    try:
        scene_file.write_text(json.dumps(payload, indent=1, allow_nan=True) + "\n")
        original_file.write_text(json.dumps(original, indent=1) + "\n")
        return f".venv/bin/python -m tools.fuzz --replay-bad {scene_file}"
    except (TypeError, ValueError):
        py_file = scene_file.with_suffix(".py")
        py_file.write_text(f"# mutated at {format_path(minimal.path)}: {minimal.what}\n"
                           f"scene = {minimal.scene!r}\n")
        original_file.write_text(json.dumps(original, indent=1) + "\n")
        return (f".venv/bin/python -c \"import airlight; exec(open('{py_file}').read()); "
                f"airlight.load_scene(scene)\"")


# --- the run -------------------------------------------------------------------------


def _still_fails(worker: Worker | None, problem: Problem, options: FuzzOptions) -> Callable[[Scene], bool]:
    backends = ("gl", "cpu") if problem.kind == "disagreement" else (problem.backend,)
    if problem.kind == "invalid":
        def invalid(scene: Scene) -> bool:
            try:
                airlight.load_scene(scene)
            except (TypeError, ValueError):
                return True
            return False
        return invalid

    def predicate(scene: Scene) -> bool:
        try:
            airlight.load_scene(scene)
        except (TypeError, ValueError):
            return False
        found = check_scene(worker, scene, backends, options)
        return any(p.signature() == problem.signature() for p in found)

    return predicate


def _describe(problems: list[Problem], signature: tuple[str, str, str]) -> str:
    return next((p.detail for p in problems if p.signature() == signature), "")


def run_valid(options: FuzzOptions, worker: Worker | None, recorder: Recorder, report: RunReport,
              progress: Progress) -> None:
    """The valid-scene part of a run."""
    for index in range(options.scenes):
        if options.deadline is not None and time.monotonic() > options.deadline:
            progress.message(f"time is up after {index} scenes")
            break
        scene = random_scene(scene_rng(options.seed, index), options.generator)
        problems = check_scene(worker, scene, options.backends, options, report)
        report.scenes += 1
        for problem in problems:
            report.problems[problem.kind] = report.problems.get(problem.kind, 0) + 1
            known = recorder.seen(problem, scene)
            if known is not None:
                known.occurrences += 1
                recorder.write_index()
                continue
            progress.message(f"scene {index}: {problem.kind} on {problem.backend}: "
                             f"{problem.detail.splitlines()[0][:200] if problem.detail else ''}")
            predicate = _still_fails(worker, problem, options)
            def note(text: str, at: int = index) -> None:
                progress.update(at, text)

            minimal, attempts = shrink(scene, predicate, budget_seconds=options.shrink_seconds, progress=note)
            backends = ("gl", "cpu") if problem.kind == "disagreement" else (problem.backend,)
            minimal_problems = (check_scene(worker, minimal, backends, options)
                                if problem.kind != "invalid" else [problem])
            finding = recorder.add(problem, index, scene, minimal, attempts,
                                   _describe(minimal_problems, problem.signature()), backends, options.demo,
                                   bad_input=False)
            progress.message(f"  -> {finding.scene_file} ({attempts} shrinking tries)")
        progress.update(index + 1, f"{len(recorder.findings)} findings")


def _bad_outcome(worker: Worker | None, mutation: Mutation, options: FuzzOptions) -> str | None:
    if options.demo is not None:
        return _judge_demo(options.demo, mutation, options.timeout)
    assert worker is not None
    outcome = worker.request("validate", mutation.scene, timeout=min(options.timeout, 30.0))
    verdict = judge(outcome.status, outcome.error_type, outcome.message, mutation)
    return "accepted" if verdict is None and outcome.status == "ok" else verdict


def _judge_demo(demo: str, mutation: Mutation, timeout: float) -> str | None:
    """The demo's answer to a bad scene file: status 2 and one line on stderr (or a render)."""
    try:
        text = json.dumps(mutation.scene, allow_nan=False)
    except (TypeError, ValueError):
        return None  # not expressible as a scene file
    with tempfile.TemporaryDirectory(prefix="airlight-fuzz-") as tmp:
        scene_file = Path(tmp) / "scene.json"
        scene_file.write_text(text)
        try:
            run = subprocess.run([demo, "--scene", str(scene_file), "--out", str(Path(tmp) / "o.pfm"),
                                  "--backend", "cpu", "--width", "4", "--height", "3"],
                                 capture_output=True, text=True, timeout=timeout, errors="replace")
        except subprocess.TimeoutExpired:
            return f"hang: no exit within {timeout:g} s"
    if any(mark in run.stderr for mark in SANITIZER_MARKS):
        return "sanitizer: " + run.stderr[-3000:]
    if run.returncode == 0:
        return "accepted"
    lines = run.stderr.strip().splitlines()
    if run.returncode != 2 or len(lines) != 1:
        return f"exit status {run.returncode} with stderr {run.stderr.strip()[:500]!r}"
    return None


def _verdict_kind(verdict: str) -> str:
    """The first word of a bad-input verdict: the exception type, crash, hang, sanitizer, exit."""
    return verdict.split(":")[0].split(" ")[0]


def _invalid_base(base: Scene, index: int, options: FuzzOptions, recorder: Recorder, report: RunReport,
                  progress: Progress) -> bool:
    """True (and an ``invalid`` finding: a generator bug) when the loader refuses the scene a
    bad input was to be made from; a mutation of it would be judged against the wrong field."""
    try:
        airlight.load_scene(base)
    except (TypeError, ValueError) as exc:
        problem = Problem("invalid", "-", f"load_scene refused a generated scene: {exc}", type(exc).__name__)
        report.problems[problem.kind] = report.problems.get(problem.kind, 0) + 1
        known = recorder.seen(problem, base)
        if known is not None:
            known.occurrences += 1
            recorder.write_index()
            return True
        progress.message(f"bad input {index}: its base scene is invalid: {exc}")
        minimal, attempts = shrink(base, _still_fails(None, problem, options),
                                   budget_seconds=min(options.shrink_seconds, 60.0))
        recorder.add(problem, 10_000_000 + index, base, minimal, attempts, problem.detail, ("-",),
                     options.demo, bad_input=False)
        return True
    return False


def run_bad(options: FuzzOptions, worker: Worker | None, recorder: Recorder, report: RunReport,
            progress: Progress) -> None:
    """The bad-input part of a run: mutations of valid scenes must be refused cleanly."""
    for index in range(options.bad_inputs):
        if options.deadline is not None and time.monotonic() > options.deadline + options.bad_input_grace:
            progress.message(f"time is up after {index} bad inputs")
            break
        rng = scene_rng(options.seed, 10_000_000 + index)
        base = random_scene(rng, options.generator)
        if _invalid_base(base, index, options, recorder, report, progress):
            continue
        mutation = mutate(base, rng, empty_key=options.generator.allows("empty_key"))
        verdict = _bad_outcome(worker, mutation, options)
        report.bad_inputs += 1
        report.bad_inputs_accepted += verdict == "accepted"
        if verdict in (None, "accepted"):
            progress.update(index + 1, f"{len(recorder.findings)} findings")
            continue
        kind = _verdict_kind(verdict)
        problem = Problem(f"bad-input-{_slug(kind)}", "loader", verdict, error_type=_slug(mutation.what)[:20])
        report.problems[problem.kind] = report.problems.get(problem.kind, 0) + 1
        known = recorder.seen(problem)
        if known is not None:
            known.occurrences += 1
        else:
            progress.message(f"bad input {index}: {verdict[:200]}")

            def same_verdict(candidate: Scene, m: Mutation = mutation, kind: str = kind) -> bool:
                v = _bad_outcome(worker, Mutation(candidate, m.path, m.what), options)
                return v not in (None, "accepted") and _verdict_kind(v) == kind

            scene, attempts = shrink(mutation.scene, same_verdict,
                                     budget_seconds=min(options.shrink_seconds, 60.0))
            minimal = Mutation(scene, mutation.path, mutation.what)
            detail = _bad_outcome(worker, minimal, options) or verdict
            recorder.add(problem, index, base, minimal, attempts, detail, ("loader",), options.demo,
                         bad_input=True)
        progress.update(index + 1, f"{len(recorder.findings)} findings")


def run(options: FuzzOptions) -> RunReport:
    """A whole run: ``options.scenes`` valid scenes, then ``options.bad_inputs`` bad ones."""
    options.out.mkdir(parents=True, exist_ok=True)
    report = RunReport(backends=options.backends)
    recorder = Recorder(options.out)
    start = time.monotonic()
    worker = (None if options.demo
              else Worker(options.out / "logs", timeout=options.timeout, fresh=options.fresh))
    try:
        if options.scenes:
            progress = Progress(options.scenes, "scenes", options.progress)
            run_valid(options, worker, recorder, report, progress)
            progress.close()
        if options.bad_inputs:
            progress = Progress(options.bad_inputs, "bad inputs", options.progress)
            run_bad(options, worker, recorder, report, progress)
            progress.close()
    finally:
        if worker is not None:
            report.worker_restarts = worker.restarts
            worker.stop()
    report.seconds = time.monotonic() - start
    report.findings = recorder.findings
    recorder.write_index()
    (options.out / "report.json").write_text(json.dumps(_report_dict(report, options), indent=1) + "\n")
    return report


def _report_dict(report: RunReport, options: FuzzOptions) -> dict[str, Any]:
    data = asdict(report)
    data["seed"] = options.seed
    data["generator"] = {**asdict(options.generator), "exclude": sorted(options.generator.exclude)}
    data["tolerance"] = options.tolerance
    data["demo"] = options.demo
    return data


def replay(paths: list[Path], options: FuzzOptions) -> int:
    """Checks each scene file on ``options.backends``; prints its problems; 1 if any."""
    worker = None if options.demo else Worker(options.out / "logs", timeout=options.timeout, fresh=True)
    failed = 0
    try:
        for path in paths:
            scene = json.loads(Path(path).read_text())
            problems = check_scene(worker, scene, options.backends, options)
            print(f"{path}: {'ok' if not problems else f'{len(problems)} problems'}")
            for p in problems:
                print(f"  {p.kind} on {p.backend}: {p.detail}")
            failed += bool(problems)
    finally:
        if worker is not None:
            worker.stop()
    return 1 if failed else 0


def replay_bad(paths: list[Path], options: FuzzOptions) -> int:
    """Replays bad-input reproducers (``{"mutated_path", "what", "scene"}`` files)."""
    from .mutate import parse_path

    failed = 0
    with Worker(options.out / "logs", timeout=options.timeout, fresh=True) as worker:
        for path in paths:
            data = json.loads(Path(path).read_text())
            mutation = Mutation(data["scene"], parse_path(data["mutated_path"]), data.get("what", ""))
            outcome = worker.request("validate", mutation.scene)
            verdict = judge(outcome.status, outcome.error_type, outcome.message, mutation)
            print(f"{path}: {outcome.status} {outcome.error_type}: {outcome.message[:300]}")
            print(f"  {'ok' if verdict is None else verdict}")
            failed += verdict is not None
    return 1 if failed else 0


def calibrate(options: FuzzOptions, sizes: tuple[tuple[int, int], ...] = ((64, 36), (16, 9), (8, 6))) -> int:
    """Renders every shipped preset on GL and CPU at ``sizes`` and prints the disagreement
    metric of each; 1 when one exceeds the tolerance."""
    failed = 0
    with Worker(options.out / "logs", timeout=max(options.timeout, 300.0)) as worker:
        for name in airlight.preset_names():
            for width, height in sizes:
                scene = airlight.preset(name)
                scene["film"] = {"width": width, "height": height}
                outs = {b: worker.request("render", scene, b) for b in ("gl", "cpu")}
                if any(o.status != "ok" or o.image is None for o in outs.values()):
                    print(f"{name} {width}x{height}: " + ", ".join(f"{b} {o.status} {o.message[:200]}"
                                                                 for b, o in outs.items()))
                    failed += 1
                    continue
                gl, cpu = outs["gl"].image, outs["cpu"].image
                assert gl is not None and cpu is not None
                d = compare.disagreement(gl, cpu, options.tolerance)
                print(f"{name:28s} {width:3d}x{height:<3d} max error {d.max_error:.2e} (all pixels "
                      f"{d.max_error_all:.2e}), bad {d.bad_pixels}, excused {d.excused_pixels}"
                      f"{'  DISAGREE' if d.disagree else ''}")
                failed += d.disagree
    return 1 if failed else 0


def summary(report: RunReport) -> str:
    """The run's figures as text."""
    counts = Counter(report.problems)
    lines = [f"{report.scenes} valid scenes ({report.renders} renders on {', '.join(report.backends)}), "
             f"{report.bad_inputs} bad inputs ({report.bad_inputs_accepted} still valid), "
             f"{report.seconds:.0f} s; worker restarts {report.worker_restarts}; "
             f"largest GL/CPU disagreement {report.max_disagreement:.2e}; "
             f"{report.cpu_fallback_frames} GL frames with loop-limit CPU fallback pixels",
             f"problems: {dict(counts) if counts else 'none'}",
             f"findings: {len(report.findings)}"]
    for f in report.findings:
        lines.append(f"  {f.id}: seen {f.occurrences}x, {f.scene_file}")
        lines.append(f"    {f.command}")
    return "\n".join(lines)


def environment_note() -> str:
    """Which backends can run here."""
    reason = airlight.gl_unavailable_reason()
    return "gl and cpu" if reason is None else f"cpu only (GL: {reason})"


__all__ = ["FuzzOptions", "Finding", "Problem", "RunReport", "calibrate", "check_scene", "environment_note",
           "replay", "replay_bad", "run", "summary"]
