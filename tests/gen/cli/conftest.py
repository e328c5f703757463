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


@pytest.fixture
def board_refusal(tmp_path, monkeypatch, run_cli):
    """``board_refusal(flags)``: runs ``bumprtl board ulx3s FLAGS --out DIR`` with the
    bitstream, part-cost and frame steps failing if reached, checks the refusal (exit 2,
    nothing on stdout, nothing written) and returns its one stderr line."""
    from bumprtl.gen.cli import board as cli_board

    def never(*args, **kw):
        raise AssertionError("a refused command reached a build step")
    for name in ("build_bitstream", "part_costs", "check_frames"):
        monkeypatch.setattr(cli_board, name, never)

    def refuse(flags):
        out = tmp_path / "refused"
        r = run_cli(["board", "ulx3s", *flags, "--out", out])
        assert r.returncode == 2, r.stdout + r.stderr
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("bumprtl: error: "), lines
        assert not out.exists() and r.stdout == ""
        return lines[0]
    return refuse
