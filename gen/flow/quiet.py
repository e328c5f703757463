"""Quiet by default: the external tools' output (Verilator's make and g++, cocotb's banners,
Yosys, nextpnr) goes to a log under build/ whose path is printed; the terminal gets a
progress line and the result. The log is shown in full when the work fails, and
``--verbose`` lets everything through.

:func:`tool_log` redirects the process's file descriptors 1 and 2, so the tools that run
as child processes (and cocotb's runner, and Python's own prints) all land in the log.
"""

import os
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

__all__ = ["tool_log"]


def _ticker(term, label, stop):
    """``label ... N s`` on the terminal, rewritten every second until ``stop``."""
    t0 = time.perf_counter()
    tty = term.isatty()
    while not stop.wait(1.0 if tty else 3600):
        term.write(f"\r{label} {time.perf_counter() - t0:.0f} s")
        term.flush()
    term.write(f"\r{label} done in {time.perf_counter() - t0:.0f} s\n")
    term.flush()


def _on_fd(stream, fd):
    """Whether ``stream`` writes to file descriptor ``fd``."""
    try:
        return stream.fileno() == fd
    except (AttributeError, OSError, ValueError):
        return False


@contextmanager
def tool_log(path, label, verbose=False, python=False):
    """Everything written to stdout/stderr inside the block (by this process and its
    children) goes to ``path``; the terminal shows ``label`` with the elapsed seconds. On an
    exception the log is copied to stderr in full, then the exception propagates.
    ``verbose``: no redirection, the tools print as they run. ``python``: this process's
    ``print`` and progress bars (``sys.stdout``/``sys.stderr``) still reach the terminal
    (a bench's table); only the child processes' output goes to the log, no ticker, and the
    log's path is named after the block, on success (a command's refusal inside the block,
    bad input, stays its one line on stderr)."""
    if verbose:
        yield None
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    term = os.fdopen(os.dup(saved[1]), "w", buffering=1)
    if not python:
        term.write(f"{label} (tool output: {path})\n")
    stop = threading.Event()
    ticker = threading.Thread(target=_ticker, args=(term, label, stop), daemon=True)
    failed = False
    streams = sys.stdout, sys.stderr
    # Python's own streams follow the redirection only when they write to fds 1 and 2 (not
    # when a caller captures them, as pytest's capsys does): only then are they replaced.
    swap = python and _on_fd(sys.stdout, 1)
    if swap:
        sys.stdout = os.fdopen(os.dup(saved[0]), "w", buffering=1)
    if python and _on_fd(sys.stderr, 2):
        sys.stderr = term
    with open(path, "w") as log:
        os.dup2(log.fileno(), 1)
        os.dup2(log.fileno(), 2)
        if not python:
            ticker.start()
        try:
            yield path
        except BaseException:
            failed = True
            raise
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            if swap:
                sys.stdout.close()
            if python:
                sys.stdout, sys.stderr = streams
                if not failed:
                    term.write(f"{label}: tool output in {path}\n")
            else:
                stop.set()
                ticker.join()
            term.close()
            if failed and path.stat().st_size:
                sys.stderr.write(f"--- {path} ---\n{path.read_text(errors='replace')}--- end of "
                                 f"{path} ---\n")
                sys.stderr.flush()
