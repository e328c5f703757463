"""Every option of every command, walked from the CLI's own parsers, says what it is for,
and where its help states a default that argparse holds, the two agree; a default path is
where the layout puts generated files (build/) or the page the command regenerates
(docs/). A help text that lies about a default, a flag without help or an output written
into a new top-level directory of the user's checkout fail here."""

import argparse
import dataclasses
import re
from pathlib import Path

import pytest

from bumprtl.gen.bench.sweep import DEFAULT_MAPS
from bumprtl.gen.cli.main import build_parser
from bumprtl.gen.cli.reference import options
from bumprtl.rtl.config import Config

ACTIONS = list(options(build_parser()))
IDS = [" ".join(path + (a.option_strings[-1] if a.option_strings else a.dest,)) for path, a in ACTIONS]


def test_the_walk_reaches_every_command():
    commands = {path[0] for path, _ in ACTIONS if path}
    assert {"emit", "render", "report", "bench", "vectors", "board", "formal", "demo",
            "recommend"} <= commands
    assert len(ACTIONS) > 200


@pytest.mark.parametrize("path, action", ACTIONS, ids=IDS)
def test_every_option_has_a_help_text(path, action):
    assert action.help and action.help.strip() and action.help != argparse.SUPPRESS


def _stated(help_text):
    """The value a help text states as its default ('(default: X)', '(default X; ...)',
    'default: X' at its end), or None."""
    m = re.search(r"\(default:? ([^;),]+)", help_text) or re.search(r"default:? ([^;),]+)$", help_text)
    return m.group(1).strip() if m else None


def _spelled(value):
    """The ways a help text writes an argparse default."""
    if isinstance(value, (list, tuple)):
        return {" ".join(map(str, value)), ",".join(map(str, value)), ", ".join(map(str, value))}
    if isinstance(value, int) and value >= 10 and value == 10 ** (len(str(value)) - 1):
        return {str(value), f"10^{len(str(value)) - 1}"}
    if isinstance(value, float) and value.is_integer():
        return {str(value), str(int(value))}
    return {str(value)}


def _prose(stated):
    """A stated default that is a description, not a value ('the scene's own', 'all of them')."""
    return re.fullmatch(r"(the|all|both|none|your|a|an|Config's|img/\S+ beside --doc|--seeds)\b.*", stated) is not None


def _config_default(action):
    """A Config flag's default is Config's (argparse holds None so that a scene's value wins)."""
    names = {f.name for f in dataclasses.fields(Config)}
    return getattr(Config(), action.dest) if action.dest in names else None


# Options whose default argparse holds as None and the command resolves after parsing (from
# the scene, the map or the board), with the default their help states.
RESOLVED = {"--flash-offset": "0x200000", "--height-scale": "4", "--sdram": "32mb",
            "--pipe-mhz": "100", "--count": "1000", "--axi-data-bits": "32",
            "--cache-block": "4", "--cache-outstanding": "64", "--cache-queue": "256",
            "--cache-sets": "64", "--cache-ways": "2", "--device": "LFE5U-85F",
            "--normal-convention": "opengl", "--load": "initial", "--simulator": "verilator",
            "--scene": "default", "--name": "bumprtl_UNIT", "--pipeline": "default",
            "--method": "exact", "--scheduler": "$BUMPRTL_SCHEDULER",
            "render --scene": "bricks", "vectors --name": "bumprtl_pipeline",
            "recommend --sweep": "build/bench/sweep.json",
            "bench sweep --maps": " ".join(f"{n}:{z}" for n, z in DEFAULT_MAPS)}

STATED = [(path, a) for path, a in ACTIONS
          if a.help and _stated(a.help) is not None and not _prose(_stated(a.help))
          and not isinstance(a.default, bool)]


def test_the_stated_defaults_are_many():
    assert len(STATED) >= 60


@pytest.mark.parametrize("path, action", STATED,
                         ids=[" ".join(p + (a.option_strings[-1] if a.option_strings else a.dest,))
                              for p, a in STATED])
def test_a_stated_default_is_the_parsers(path, action):
    """A value the help states as the default is argparse's default; where argparse holds
    None, Config's (a Config flag) or the one the command resolves (``RESOLVED``)."""
    stated = _stated(action.help)
    if action.default is not None:
        value = stated if stated in _spelled(action.default) else stated.split()[0].rstrip(":")
        assert value in _spelled(action.default), (action.help, action.default)
    elif _config_default(action) is not None:
        assert stated in _spelled(_config_default(action)), (action.help, _config_default(action))
    else:
        flag = action.option_strings[-1]
        key = " ".join(path + (flag,))
        want = RESOLVED[key] if key in RESOLVED else RESOLVED.get(flag)
        assert want is not None and (stated == want or stated.split()[0].rstrip(":") == want), \
            (key, action.help)


PATHS = [(path, a) for path, a in ACTIONS if isinstance(a.default, Path)]


@pytest.mark.parametrize("path, action", PATHS,
                         ids=[" ".join(p + (a.option_strings[-1],)) for p, a in PATHS])
def test_a_default_path_is_under_build_or_docs(path, action):
    assert not action.default.is_absolute()
    assert action.default.parts[0] in ("build", "docs"), action.default
