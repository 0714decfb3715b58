"""The README's Python example runs as written (files go to a temporary folder,
the walk takes fewer steps)."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_example_runs(tmp_path, monkeypatch):
    block = re.search(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    assert block, "README has no Python example"
    code = block.group(1).replace("range(0, -50, -1)", "range(0, -50, -25)")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, str(README), "exec"), {})
    assert (tmp_path / "fog.png").stat().st_size > 0
    assert (tmp_path / "fog.pfm").stat().st_size > 0


def test_readme_lists_exactly_the_shipped_presets():
    """The presets the README's API section names are the scenes shipped (no name that does not
    exist, none left out)."""
    import airlight

    text = README.read_text(encoding="utf-8")
    section = text[text.index("- `preset_names()`"):text.index("- `rainbow_phase(")]
    named = set(re.findall(r"`([a-z_0-9]+)`", section)) - {"preset_names", "preset", "scenes"}
    assert named == set(airlight.preset_names())
