"""Fixtures and helpers of the command-line tests."""

import argparse
import importlib

import pytest

from bumprtl.gen.cli.flags import add_config_flags


def config_parser(**kw):
    """A parser holding only the Config flags (``add_config_flags(parser, **kw)``) that raises
    argparse errors instead of exiting."""
    p = argparse.ArgumentParser(prog="t", exit_on_error=False)
    add_config_flags(p, **kw)
    return p


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
