"""Animating a phase lobe's g keeps memory bounded (issue 27, item 10): each distinct g
used to build tables kept for the process's life (40 values: 80 tables, +11 MB). The
tables are now cached for the last 8 lobes (cpp/tables.hpp, TableCache), and a lobe
dropped from the cache is rebuilt, identically, when it comes back."""

from __future__ import annotations

import numpy as np
import pytest

import airlight

G_VALUES = [round(0.05 * k, 2) for k in range(1, 13)]  # 12 distinct lobes


def hg_scene(g: float) -> dict:
    return {"film": {"width": 8, "height": 6},
            "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 60},
            "medium": {"sigma_t": 0.05, "albedo": 0.9, "phase": {"type": "hg", "g": g}},
            "lights": [{"type": "point", "position": [0, 5, -10], "intensity": 100}]}


@pytest.mark.slow
def test_animating_g_keeps_at_most_8_lobes_of_tables(renderer):
    first = renderer.render(hg_scene(G_VALUES[0]))
    for g in G_VALUES[1:]:
        renderer.render(hg_scene(g))
    stats = airlight.table_stats()
    names = [f"phase_moments g={g:g}" for g in G_VALUES]
    assert all(name in stats for name in names), sorted(stats)
    resident = [name for name in names if stats[name]["resident"]]
    assert resident == names[-8:]  # the least recently used went first
    # g = 0.05 was dropped: it is rebuilt, and renders as before.
    again = renderer.render(hg_scene(G_VALUES[0]))
    np.testing.assert_array_equal(again, first)
    assert airlight.table_stats()[names[0]]["builds"] >= 2
