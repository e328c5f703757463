"""A core install (``pip install bumprtl``, no extra) simulated in this venv, without network.

:func:`hidden` computes what a core install lacks: every installed distribution outside the
closure of pyproject.toml's ``dependencies`` (each core requirement and, recursively, the
requirements its installed metadata declares, markers evaluated here) and the top-level
modules those distributions install. :func:`run_cli` runs ``bumprtl`` commands in ONE
subprocess whose ``sitecustomize`` (on PYTHONPATH) hides them: importing one raises
ModuleNotFoundError, and ``importlib.metadata`` no longer finds them. Each command runs
in-process through ``main(argv)`` with file descriptors 1 and 2 captured (the tools' and
tool_log's output included); the result is ``[{argv, code, out, err, seconds}]``.

tests/tools/compat.py does the same with the real wheel in a fresh venv per Python.
"""

import importlib.metadata as md
import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[3]


def _norm(name):
    return re.sub(r"[-_.]+", "-", name).lower()


def core_distributions():
    """Normalized names of the distributions a core install holds (bumprtl's own too)."""
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    seen, todo = {"bumprtl"}, [Requirement(d) for d in deps]
    while todo:
        req = todo.pop()
        if req.marker is not None and not req.marker.evaluate({"extra": ""}):
            continue
        key = _norm(req.name)
        if key in seen and not req.extras:
            continue
        seen.add(key)
        for line in md.requires(req.name) or []:
            sub = Requirement(line)
            if sub.marker is None or any(sub.marker.evaluate({"extra": e})
                                         for e in ("", *req.extras)):
                todo.append(sub)
    return seen


def _top_level(dist):
    """The top-level import names a distribution installs (top_level.txt, else its files)."""
    names = set((dist.read_text("top_level.txt") or "").split())
    for f in dist.files or ():
        first = f.parts[0] if f.parts else ""
        if first in ("..", "__pycache__") or first.endswith((".dist-info", ".data", ".pth")):
            continue
        if len(f.parts) > 1:
            names.add(first)
        elif first.endswith(".py") or ".cpython-" in first or first.endswith((".so", ".abi3.so")):
            names.add(first.split(".")[0])
    return {n for n in names if n.isidentifier()}


def hidden():
    """``(modules, distributions)`` a core install lacks: the top-level modules of every
    installed distribution outside :func:`core_distributions` (none that a core
    distribution or the standard library also provides), and those distributions' names."""
    core = core_distributions()
    keep, hide, dists = set(sys.stdlib_module_names), set(), set()
    for dist in md.distributions():
        name = _norm(dist.metadata["Name"])
        (keep if name in core else hide).update(_top_level(dist))
        if name not in core:
            dists.add(name)
    return sorted(hide - keep), sorted(dists)


# sitecustomize.py of the subprocess: BUMPRTL_HIDE names a JSON file {modules, dists}.
SITECUSTOMIZE = '''
import importlib.metadata, json, os, re, sys
_spec = json.load(open(os.environ["BUMPRTL_HIDE"]))
_MODULES, _DISTS = set(_spec["modules"]), set(_spec["dists"])

class _NotInstalled:
    """A core install: the optional packages are not there."""
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in _MODULES:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
    def find_distributions(self, context=None):
        return ()

sys.meta_path.insert(0, _NotInstalled())
_distribution = importlib.metadata.distribution

def distribution(name):
    if re.sub(r"[-_.]+", "-", name).lower() in _DISTS:
        raise importlib.metadata.PackageNotFoundError(name)
    return _distribution(name)

importlib.metadata.distribution = distribution
'''

# The subprocess's main: each argv through bumprtl's main() with fds 1 and 2 in files.
RUNNER = '''
import json, os, sys, tempfile, time
from bumprtl.gen.cli.main import main

def run(argv):
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        sys.stdout.flush(); sys.stderr.flush()
        saved, t0 = (os.dup(1), os.dup(2)), time.perf_counter()
        os.dup2(out.fileno(), 1); os.dup2(err.fileno(), 2)
        try:
            try:
                code = main(argv)
            except SystemExit as e:
                code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
            except BaseException as e:
                import traceback; traceback.print_exc()
                code = f"raised {type(e).__name__}"
        finally:
            sys.stdout.flush(); sys.stderr.flush()
            os.dup2(saved[0], 1); os.dup2(saved[1], 2)
            os.close(saved[0]); os.close(saved[1])
        out.seek(0); err.seek(0)
        return {"argv": argv, "code": code, "out": out.read(), "err": err.read(),
                "seconds": time.perf_counter() - t0}

commands = json.load(open(sys.argv[1]))
json.dump([run(argv) for argv in commands], open(sys.argv[2], "w"))
'''


def run_cli(commands, tmp_path, hide=None, timeout=300):
    """Run each argv of ``commands`` through ``bumprtl`` in one subprocess, in ``tmp_path``,
    with ``hide`` (default :func:`hidden`) not installed; ``[{argv, code, out, err}]``."""
    modules, dists = hidden() if hide is None else hide
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text(SITECUSTOMIZE)
    (tmp_path / "hide.json").write_text(json.dumps({"modules": modules, "dists": dists}))
    (tmp_path / "commands.json").write_text(json.dumps(commands))
    env = dict(os.environ, BUMPRTL_HIDE=str(tmp_path / "hide.json"), BUMPRTL_PROGRESS="0",
               PYTHONPATH=os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")]))
    r = subprocess.run([sys.executable, "-c", RUNNER, str(tmp_path / "commands.json"),
                        str(tmp_path / "results.json")], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, r.stderr
    return json.loads((tmp_path / "results.json").read_text())
