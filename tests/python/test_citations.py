"""Every citation in the repository resolves inside it: a path that a comment, docstring or document
names (``effects/daytime/physics.md``, ``shaders/geometry.glsl``, ...) exists, and a cited section
(``effects/lamp_airlight/physics.md section 3``) is a numbered heading of that file. The physics the
code cites lives in the repository (docs/conventions.md, effects/<name>/physics.md), not outside."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TOP_DIRS = ("cpp", "shaders", "effects", "tests", "docs", "benchmarks", "scenes", "include", "python",
            "examples", "tools", "cmake", "scripts")
TEXT_SUFFIXES = {".py", ".md", ".cpp", ".hpp", ".glsl", ".comp", ".frag", ".vert", ".txt", ".cmake", ".sh",
                 ".toml", ".pyi", ".inc"}
_TOP = "|".join(TOP_DIRS)
PATH_RE = re.compile(rf"(?<![\w/.-])((?:{_TOP})/[\w./-]*\w)")
SECTION_RE = re.compile(rf"(?<![\w/.-])((?:{_TOP})/[\w./-]*\.md),? sections? (\d+)")


def tracked_text_files() -> list[Path]:
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [ROOT / f for f in out.split() if Path(f).suffix in TEXT_SUFFIXES and (ROOT / f).is_file()]


def citations(pattern: re.Pattern[str]) -> list[tuple[str, int, re.Match[str]]]:
    found = []
    for path in tracked_text_files():
        for lineno, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            for m in pattern.finditer(line):
                found.append((str(path.relative_to(ROOT)), lineno, m))
    return found


def test_the_repository_has_files_to_check():
    assert len(tracked_text_files()) > 100
    assert len(citations(PATH_RE)) > 200


def test_every_cited_path_exists():
    missing = []
    for where, lineno, m in citations(PATH_RE):
        cited = m.group(1).rstrip(".")
        if cited.endswith("_"):  # a family of files named by its prefix (scenes/day_*)
            if any((ROOT / cited).parent.glob(Path(cited).name + "*")):
                continue
        if not (ROOT / cited).exists():
            missing.append(f"{where}:{lineno}: {cited}")
    assert not missing, "citations of files that do not exist:\n" + "\n".join(missing)


def headings(md: Path) -> set[int]:
    numbers = set()
    for line in md.read_text().splitlines():
        m = re.match(r"#+\s+(?:Section\s+)?(\d+)[.):\s]", line)
        if m:
            numbers.add(int(m.group(1)))
    return numbers


def test_every_cited_section_exists():
    missing = []
    for where, lineno, m in citations(SECTION_RE):
        md = ROOT / m.group(1)
        if md.exists() and int(m.group(2)) not in headings(md):
            missing.append(f"{where}:{lineno}: {m.group(1)} section {m.group(2)}")
    assert not missing, "citations of sections that do not exist:\n" + "\n".join(missing)


@pytest.mark.parametrize("name", ["MODELS.md"])
def test_no_citation_of_notes_outside_the_repository(name):
    hits = [f"{p.relative_to(ROOT)}:{i}" for p in tracked_text_files() if p.name != Path(__file__).name
            for i, line in enumerate(p.read_text(errors="replace").splitlines(), 1) if name in line]
    assert not hits, (f"{name} is not in the repository; cite docs/ or effects/<name>/physics.md:\n"
                      + "\n".join(hits))
