"""Fixtures of the command-line tests."""

import importlib

import pytest


@pytest.fixture
def import_fails(monkeypatch):
    """``import_fails(module, package)``: from then on ``importlib.import_module(module)``
    raises the ImportError of a missing ``package`` (the other modules import as usual)."""
    real = importlib.import_module

    def fails(module, package):
        def fake(name, *args):
            if name == module:
                raise ImportError(f"No module named {package!r}", name=package)
            return real(name, *args)
        monkeypatch.setattr(importlib, "import_module", fake)
    return fails
