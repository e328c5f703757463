"""``--verbose`` on every kind of ``bumprtl bench`` and ``bumprtl report``: the kind runs
inside gen/flow/quiet.py's :func:`~bumprtl.gen.flow.quiet.tool_log` unless it is given."""

import functools
from pathlib import Path

from bumprtl.gen.flow.quiet import tool_log

__all__ = ["quiet_commands"]


def quiet_commands(kinds, log_dir):
    """Give every subcommand parser of ``kinds`` (an argparse subparsers action) a
    ``--verbose`` flag and run its ``func`` inside :func:`tool_log` (``python=True``): the
    child processes' output goes to ``log_dir/KIND.log``, the command's own tables and
    progress bars stay on the terminal."""
    for kind, parser in kinds.choices.items():
        parser.add_argument("--verbose", action="store_true",
                            help="let the tools' output through (by default it goes to "
                                 f"{log_dir}/{kind}.log, shown in full on a failure)")
        parser.set_defaults(func=_quiet(parser.get_default("func"), Path(log_dir) / f"{kind}.log",
                                        f"{Path(log_dir).name} {kind}"))


def _quiet(func, log, label):
    @functools.wraps(func)
    def run(args):
        if args.verbose:
            return func(args)
        with tool_log(log, label, python=True):
            return func(args)
    return run
