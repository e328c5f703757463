"""``make compat``: the wheel on every Python the project supports that this machine has.

Builds the wheel once (``pip wheel --no-deps``), then for each of Python 3.11, 3.12, 3.13
found (pyenv's ``$PYENV_ROOT/versions/3.X.*``, else ``python3.X`` on PATH) makes a fresh
venv under ``build/compat/``, installs the wheel WITHOUT any extra (``pip install
bumprtl``: the core, as a user's first install) and runs, in one process of that venv
(tests/gen/cli/core_install.py's runner, each command through ``main(argv)`` with file
descriptors 1 and 2 captured):

* ``bumprtl --version`` (the wheel's version), ``--help`` and every command's and kind's
  ``--help`` (the list from this checkout's parser): exit 0, usage on stdout;
* the commands of the core (tests/gen/cli/test_core_install.py's CORE, every ``emit``
  unit, ``demo --no-rtl``): exit 0 and the file each writes;
* the commands that need an extra (test_core_install.py's NEEDS_EXTRA, ``bench golden``):
  exactly one line on stderr naming the extra, exit 2.

Why it missed the psutil crash of a core install (every command, ``--version`` included,
on 3.11 to 3.13): make compat is opt-in and had last run before gen/tools/jobs.py (module-level
``import psutil``) landed, and it tried four commands only. make test now holds the same
check without network (tests/gen/cli/test_core_install.py: the optional distributions
hidden in this venv); this script is the real wheel on each real interpreter.

Prints the table (Python x command: ``ok``, ``names [extra]`` or ``FAILED``) and writes it
to ``build/compat/report.txt``; pip's output and each failing command's output go to
``build/compat/<version>.log``. Exit 1 when a found interpreter fails, 0 otherwise.
"""

import glob
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from tests.gen.cli.core_install import RUNNER  # noqa: E402
from tests.gen.cli.test_core_install import CORE, NEEDS_EXTRA, command_paths  # noqa: E402

VERSIONS = ("3.11", "3.12", "3.13")
OUT = ROOT / "build" / "compat"
EMITS = ("rotation", "illumination", "palette", "fetch")          # CORE holds pipeline, sincos
# (argv, what passes): ("ok", file written or None), ("help", None) or ("extra", name)
CHECKS = ([(["--version"], ("version", None)), (["--help"], ("help", None))]
          + [([*p, "--help"], ("help", None)) for p in command_paths()]
          + [(argv, ("ok", writes)) for argv, writes in CORE]
          + [(["emit", unit, "--out", "rtl"], ("ok", f"rtl/bumprtl_{unit}.v")) for unit in EMITS]
          + [(["demo", "--no-rtl", "--size", "16", "--out", "demo"], ("ok", "demo/report.txt"))]
          + [(argv, ("extra", extra)) for argv, extra in NEEDS_EXTRA]
          + [(["bench", "golden", "--pixels", "1000"], ("extra", "bench"))])


def find_python(version):
    root = os.environ.get("PYENV_ROOT", str(Path.home() / ".pyenv"))
    found = sorted(glob.glob(f"{root}/versions/{version}.*/bin/python{version}"),
                   key=lambda p: [int(x) for x in Path(p).parents[1].name.split(".") if x.isdigit()])
    if found:
        return found[-1]
    return shutil.which(f"python{version}")


def _run(argv, log, **kw):
    log.write(f"$ {' '.join(map(str, argv))}\n")
    log.flush()
    r = subprocess.run([str(a) for a in argv], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True, **kw)
    log.write(r.stdout)
    log.flush()
    return r


def build_wheel(log):
    dist = OUT / "dist"
    shutil.rmtree(dist, ignore_errors=True)
    r = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", dist, ROOT], log)
    if r.returncode:
        raise SystemExit(f"compat: the wheel did not build; see {log.name}")
    return next(dist.glob("bumprtl-*.whl"))


def verdict(result, check, work, version):
    """``ok`` / ``names [extra]`` when ``result`` passes ``check``, else ``FAILED: why``."""
    kind, arg = check
    code, out, err = result["code"], result["out"], result["err"]
    lines = err.splitlines()
    if kind == "version":
        return "ok" if code == 0 and out == f"bumprtl {version}\n" else f"FAILED: exit {code}"
    if kind == "help":
        ok = code == 0 and out.startswith("usage: bumprtl") and "needs the [" not in out
        return "ok" if ok else f"FAILED: exit {code}"
    if kind == "ok":
        ok = code == 0 and (arg is None or (work / arg).exists())
        return "ok" if ok else f"FAILED: exit {code}" + (f", no {arg}" if code == 0 else "")
    ok = code == 2 and len(lines) == 1 and f"pip install 'bumprtl[{arg}]'" in lines[0]
    return f"names [{arg}]" if ok else f"FAILED: exit {code}, {len(lines)} stderr lines"


def smoke(python, wheel, version):
    """``(install ok, {command: verdict})`` of one interpreter."""
    venv = OUT / f"py{version}"
    work = OUT / f"work{version}"
    for d in (venv, work):
        shutil.rmtree(d, ignore_errors=True)
    work.mkdir(parents=True)
    py = venv / "bin" / "python"
    with open(OUT / f"{version}.log", "w") as log:
        for argv in ([python, "-m", "venv", venv], [py, "-m", "pip", "install", "-q", wheel]):
            if _run(argv, log).returncode:
                return False, {}
        (work / "commands.json").write_text(json.dumps([argv for argv, _ in CHECKS]))
        env = dict(os.environ, BUMPRTL_PROGRESS="0")
        env.pop("PYTHONPATH", None)
        r = _run([py, "-c", RUNNER, work / "commands.json", work / "results.json"], log,
                 cwd=work, env=env)
        if r.returncode:
            return False, {}
        results = json.loads((work / "results.json").read_text())
        want = wheel.name.split("-")[1]
        verdicts = {}
        for (argv, check), result in zip(CHECKS, results, strict=True):
            v = verdict(result, check, work, want)
            verdicts[" ".join(argv)] = v
            if v.startswith("FAILED"):
                log.write(f"--- {' '.join(argv)}: {v}\nstdout:\n{result['out']}\nstderr:\n"
                          f"{result['err']}\n")
    return True, verdicts


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    with open(OUT / "wheel.log", "w") as log:
        wheel = build_wheel(log)
    print(f"compat: {wheel.name}, installed without extras (logs in {OUT.relative_to(ROOT)}/)")
    columns, failed, notes = {}, False, []
    for version in VERSIONS:
        python = find_python(version)
        if python is None:
            notes.append(f"Python {version}: skipped, no interpreter found")
            continue
        t0 = time.perf_counter()
        installed, verdicts = smoke(python, wheel, version)
        bad = [c for c, v in verdicts.items() if v.startswith("FAILED")]
        failed |= not installed or bool(bad)
        columns[version] = verdicts
        notes.append(f"Python {version} ({python}): "
                     + ("install or runner FAILED" if not installed else
                        f"{len(verdicts) - len(bad)} of {len(verdicts)} passed")
                     + f" in {time.perf_counter() - t0:.0f} s; see build/compat/{version}.log")
        print(f"  {notes[-1]}", flush=True)
    versions = list(columns)
    table = ["| command | " + " | ".join(f"Python {v}" for v in versions) + " |",
             "|---|" + "---|" * len(versions)]
    for argv, _ in CHECKS:
        cmd = " ".join(argv)
        table.append(f"| `bumprtl {cmd}` | "
                     + " | ".join(columns[v].get(cmd, "-") for v in versions) + " |")
    text = "\n".join(table + [""] + notes) + "\n"
    (OUT / "report.txt").write_text(text)
    print(text, end="")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
