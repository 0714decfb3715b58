"""Every benchmark and analysis script the docs give a command for starts: its imports resolve from
the command line (outside pytest, whose conftest puts tests/python on the path) and `--help` exits 0.
A script that imports a test module or a sibling effect's analysis breaks silently when those move;
this found six such (four benches that import a test module which imports shared_results, two table
analyses that import the lamp airlight's after it moved into effects/lamp_airlight/docs)."""

from __future__ import annotations

import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted([*ROOT.glob("effects/*/bench/*.py"), *ROOT.glob("effects/*/docs/*.py"),
                  *ROOT.glob("benchmarks/*.py")])


def _help(script: Path) -> tuple[Path, int, str]:
    run = subprocess.run([sys.executable, str(script), "--help"], cwd=ROOT, capture_output=True, text=True,
                         timeout=300)
    return script, run.returncode, (run.stderr.strip().splitlines() or [""])[-1]


@pytest.mark.slow  # about 47 interpreters, 20-40 s
def test_every_benchmark_and_analysis_script_starts_from_the_command_line() -> None:
    assert len(SCRIPTS) > 40  # the globs still find the scripts
    with ThreadPoolExecutor(max_workers=2) as pool:  # one process per script: their path set-ups differ
        results = list(pool.map(_help, SCRIPTS))
    failed = [f"{script.relative_to(ROOT)}: rc {rc}: {last}" for script, rc, last in results if rc != 0]
    assert not failed, "\n".join(failed)
