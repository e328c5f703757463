"""``make compat``: the wheel on every Python the project supports that this machine has.

Builds the wheel once (``pip wheel --no-deps``), then for each of Python 3.11, 3.12, 3.13
found (pyenv's ``$PYENV_ROOT/versions/3.X.*``, else ``python3.X`` on PATH) makes a fresh
venv under ``build/compat/``, installs the wheel (the core only: ``pip install bumprtl``)
and runs the smoke subset:

* ``bumprtl --version`` is the wheel's version;
* ``bumprtl emit pipeline`` writes the default pipeline (Verilog, sidecar, map image);
* ``bumprtl render --model fixed`` draws the default scene with the bit-exact model;
* ``bumprtl bench golden`` without the [bench] extra says so in one line and exits 2.

Prints one line per interpreter (passed, failed or skipped: not found) and writes the table
to ``build/compat/report.txt``; pip's and the commands' output go to
``build/compat/<version>.log``. Exit 1 when a found interpreter fails, 0 otherwise.
"""

import glob
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

VERSIONS = ("3.11", "3.12", "3.13")
ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "build" / "compat"


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


def smoke(python, wheel, version):
    venv = OUT / f"py{version}"
    shutil.rmtree(venv, ignore_errors=True)
    work = OUT / f"work{version}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    bin_ = venv / "bin"
    want = wheel.name.split("-")[1]
    with open(OUT / f"{version}.log", "w") as log:
        steps = [
            ("venv", [python, "-m", "venv", venv], None),
            ("install", [bin_ / "python", "-m", "pip", "install", wheel], None),
            ("--version", [bin_ / "bumprtl", "--version"], lambda r: r.stdout.strip() == f"bumprtl {want}"),
            ("emit pipeline", [bin_ / "bumprtl", "emit", "pipeline", "--out", work / "rtl"],
             lambda r: (work / "rtl" / "bumprtl_pipeline.v").exists()),
            ("render --model fixed", [bin_ / "bumprtl", "render", "--model", "fixed", "--size", "64",
                                      "--out", work / "fixed.png"],
             lambda r: (work / "fixed.png").exists()),
            ("missing extra", [bin_ / "bumprtl", "bench", "golden"],
             lambda r: r.returncode == 2 and "pip install 'bumprtl[bench]'" in r.stdout),
        ]
        for name, argv, check in steps:
            r = _run(argv, log, cwd=work)
            ok = check(r) if check else r.returncode == 0
            if not ok:
                return False, f"{name} failed (exit {r.returncode})"
    return True, "passed"


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    with open(OUT / "wheel.log", "w") as log:
        wheel = build_wheel(log)
    print(f"compat: {wheel.name} (logs in {OUT.relative_to(ROOT)}/)")
    rows, failed = [], False
    for version in VERSIONS:
        python = find_python(version)
        if python is None:
            rows.append((version, "-", "skipped: no interpreter found", "-"))
        else:
            t0 = time.perf_counter()
            ok, what = smoke(python, wheel, version)
            failed |= not ok
            rows.append((version, python, what if ok else f"FAILED: {what}; see build/compat/{version}.log",
                         f"{time.perf_counter() - t0:.0f} s"))
        print(f"  Python {rows[-1][0]}: {rows[-1][2]} ({rows[-1][1]}, {rows[-1][3]})", flush=True)
    table = ["| Python | Interpreter | Result | Time |", "|---|---|---|---|"]
    table += [f"| {v} | `{p}` | {w} | {t} |" for v, p, w, t in rows]
    (OUT / "report.txt").write_text("\n".join(table) + "\n")
    skipped = [v for v, _, w, _ in rows if w.startswith("skipped")]
    print(f"compat: skipped {', '.join(skipped) if skipped else 'none'}; table in build/compat/report.txt")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
