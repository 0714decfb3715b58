"""The package's public surface: ``__all__``, ``__version__``, and nothing leaked from its imports."""

from __future__ import annotations

import inspect
from importlib import metadata

import pytest

import airlight


def test_all_lists_unique_names() -> None:
    assert isinstance(airlight.__all__, list)
    assert all(isinstance(name, str) for name in airlight.__all__)
    assert len(airlight.__all__) == len(set(airlight.__all__))


@pytest.mark.parametrize("name", airlight.__all__)
def test_every_public_name_exists_and_callables_are_documented(name: str) -> None:
    assert hasattr(airlight, name), f"airlight.__all__ lists {name!r}, which airlight lacks"
    obj = getattr(airlight, name)
    if inspect.isclass(obj) or inspect.isroutine(obj):
        # Its own docstring: a class without one would otherwise show its base class's.
        assert obj.__doc__ and obj.__doc__.strip(), f"airlight.{name} has no docstring"


def test_public_callables_live_in_the_airlight_package() -> None:
    # The re-exports are airlight's own functions and classes, not something imported by accident.
    for name in airlight.__all__:
        obj = getattr(airlight, name)
        if inspect.isclass(obj) or inspect.isroutine(obj):
            assert obj.__module__.split(".")[0] == "airlight", (name, obj.__module__)


def test_version_is_the_installed_metadata_version() -> None:
    assert isinstance(airlight.__version__, str)
    assert airlight.__version__ == metadata.version("airlight")


@pytest.mark.parametrize("name", ["np", "json", "Any", "Path", "os", "sys"])
def test_implementation_imports_do_not_leak_into_the_package(name: str) -> None:
    assert not hasattr(airlight, name), f"airlight.{name} leaks an implementation import"


def test_star_import_gives_exactly_all() -> None:
    namespace: dict[str, object] = {}
    exec("from airlight import *", namespace)
    namespace.pop("__builtins__", None)
    assert sorted(namespace) == sorted(airlight.__all__)
