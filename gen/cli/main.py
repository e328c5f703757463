"""The ``bumprtl`` command: emit Verilog, render, report, bench.

Every subcommand lives in its own module with an ``add_parser(subparsers)`` function.
Bad input (a :class:`~bumprtl.rtl.config.BumpError`) prints one line naming the parameter
and its allowed range and exits with status 2; there is no traceback.
"""

import argparse
import sys

from bumprtl.rtl.config import BumpError
from bumprtl.gen.cli import bench, board, doctor, emit, formal, report
from bumprtl.sim.toolchain import ToolMissing
from bumprtl.gen.render import demo, images
from bumprtl.gen.report import recommend

# Subcommand modules, in the order `bumprtl --help` lists them.
COMMANDS = [doctor, demo, images, emit, bench, report, recommend, formal, board]


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        print(f"bumprtl: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def build_parser():
    parser = _Parser(prog="bumprtl",
                     description="Bump-mapping hardware generator and verification suite "
                                 "(Lee et al. 2003 angular operation; Tarini et al. 2000 "
                                 "quantized normal maps).")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module in COMMANDS:
        module.add_parser(sub)
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args) or 0
    except (BumpError, ToolMissing) as e:
        print(f"bumprtl: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("bumprtl: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
