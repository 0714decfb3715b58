"""``airlight.__version__``: the installed distribution's version."""

from __future__ import annotations

from importlib import metadata


def _installed_version() -> str:
    """The version in the installed package metadata; pyproject.toml's when there is none
    (the package imported from a source tree that was never installed)."""
    try:
        return metadata.version("airlight")
    except metadata.PackageNotFoundError:
        return "0.1.0"


__version__ = _installed_version()
