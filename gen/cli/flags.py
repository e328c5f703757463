"""Command-line flags for the Config fields, shared by every subcommand."""

import argparse
import dataclasses

from bumprtl.rtl.config import Config

__all__ = ["add_config_flags", "config_from_args"]


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
