"""The ``bumprtl`` command: emit Verilog, render, report, bench.

Every subcommand lives in its own module with an ``add_parser(subparsers)`` function.
Bad input (a :class:`~bumprtl.rtl.config.BumpError`) prints one line naming the parameter
and its allowed range and exits with status 2; there is no traceback.
"""

import argparse
import dataclasses
import importlib
import sys

from ..rtl.config import BumpError, Config
from .toolchain import ToolMissing

# Subcommand modules, in the order `bumprtl --help` lists them.
COMMANDS = ["doctor", "demo", "render", "emit_cmd", "bench", "report", "recommend"]


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        print(f"bumprtl: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def add_config_flags(parser, fields=None):
    """``--angle-bits``, ``--frac-bits``, ... for the Config fields (all by default).

    Defaults are None, so :func:`config_from_args` can tell "not given" from a value and
    fall back to the Config default; the help text shows that default.
    """
    defaults = Config()
    for f in dataclasses.fields(Config):
        if fields is not None and f.name not in fields:
            continue
        flag = "--" + f.name.replace("_", "-")
        default = getattr(defaults, f.name)
        if isinstance(default, bool):
            parser.add_argument(flag, dest=f.name, action=argparse.BooleanOptionalAction,
                                default=None, help=f"default: {default}")
        else:
            parser.add_argument(flag, dest=f.name, type=type(default), default=None,
                                metavar=f.name.upper(), help=f"default: {default}")


def config_from_args(args, base=None):
    """A validated Config from the flags that were given (the rest keep their defaults)."""
    given = {f.name: getattr(args, f.name) for f in dataclasses.fields(Config)
             if getattr(args, f.name, None) is not None}
    return (base or Config()).replace(**given)


def build_parser():
    parser = _Parser(prog="bumprtl",
                     description="Bump-mapping hardware generator and verification suite "
                                 "(Lee et al. 2003 angular operation; Tarini et al. 2000 "
                                 "quantized normal maps).")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"{__package__}.{name}").add_parser(sub)
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
