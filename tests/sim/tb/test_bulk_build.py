"""The bulk wrapper's build options and cache (sim/tb/bulk_build.py) without a simulator:
each option out of range refused naming it, the Verilator-only options refused on Icarus,
the arguments each option adds, cocotb's runner without ``--public-flat-rw`` and with the
C++ main swapped in, and one build per digest (a second call reuses the directory, another
option builds anew) with the make variables in the environment while it builds."""

import json
import os

import pytest

from bumprtl.gen.flow.units import build_unit
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.tb import bulk_build
from bumprtl.sim.tb.bulk_build import (
    DPI_CPP,
    MAIN_CPP,
    TIMING_ARGS,
    VERILATOR_ARGS,
    build,
    build_args,
    build_options,
    runners,
)
from bumprtl.sim.tb.bulk_wrapper import PERIOD


@pytest.mark.parametrize("sim, kw, message", [
    ("xcelium", {}, "simulator must be one of icarus, verilator, got 'xcelium'"),
    ("verilator", {"clock": "vpi"}, "clock must be one of verilog, cxx, got 'vpi'"),
    ("icarus", {"io": "mmap"}, "io must be one of file, dpi, got 'mmap'"),
    ("icarus", {"clock": "cxx"}, "clock 'cxx' needs Verilator's C++ build; on icarus clock "
                                 "must be 'verilog'"),
    ("icarus", {"io": "dpi"}, "io 'dpi' needs Verilator's C++ build; on icarus io must be 'file'"),
    ("icarus", {"opt_fast": "-O2"}, "opt_fast and extra are Verilator build options, not icarus's"),
    ("icarus", {"extra": ["-g"]}, "opt_fast and extra are Verilator build options"),
    ("verilator", {"opt_fast": "O2"}, "opt_fast must be one g++ flag such as -Os or -O2"),
    ("verilator", {"opt_fast": "-O2 -g"}, "got '-O2 -g'"),
])
def test_bad_build_options_are_refused_naming_the_option(sim, kw, message):
    with pytest.raises(BumpError) as e:
        build_options(sim, **kw)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_options_default_per_simulator_and_the_given_ones_over_them():
    assert build_options("icarus") == {"clock": "verilog", "io": "file", "opt_fast": None,
                                       "extra": ()}
    assert build_options("verilator", io="file", extra=["--threads", 2]) == {
        "clock": "cxx", "io": "file", "opt_fast": "-Os", "extra": ("--threads", "2")}


def test_build_args_per_option():
    assert build_args("icarus") == []
    period = f"-DBULK_PERIOD={PERIOD * 1000}"                # the clock period in ps ticks
    assert build_args("verilator") == [*VERILATOR_ARGS, "-CFLAGS", period,
                                       "+define+BUMPRTL_BULK_DPI", str(DPI_CPP)]
    own = build_args("verilator", clock="verilog", io="file", extra=("--threads", "2"))
    assert own == [*VERILATOR_ARGS, *TIMING_ARGS, "--threads", "2"]
    assert period not in own


def test_the_verilator_runner_drops_public_flat_rw_and_swaps_in_the_main(monkeypatch):
    cls = runners()["verilator"]
    base = cls.__mro__[1]
    cocotb_main = "/site/cocotb/share/lib/verilator/verilator.cpp"
    monkeypatch.setattr(base, "_build_command", lambda self: [
        ["verilator", "--public-flat-rw", "-cc", cocotb_main, "top.v"], ["make"]])
    runner = cls()
    assert runner._build_command() == [["verilator", "-cc", cocotb_main, "top.v"], ["make"]]
    runner.main = MAIN_CPP
    assert runner._build_command()[0] == ["verilator", "-cc", str(MAIN_CPP), "top.v"]
    monkeypatch.setattr(base, "_build_command", lambda self: [["verilator", "top.v"]])
    with pytest.raises(AssertionError, match="cocotb's Verilator main not found"):
        runner._build_command()
    assert runners()["icarus"].__name__ == "Icarus"


class _Runner:
    builds = []
    main = None

    def build(self, **kw):
        _Runner.builds.append({**kw, "main": self.main, "MAKEFLAGS": os.environ.get("MAKEFLAGS")})


def test_one_build_per_digest_reused_and_rebuilt_for_other_options(monkeypatch, tmp_path):
    monkeypatch.setattr(bulk_build, "require", lambda tool: f"/bin/{tool}")
    monkeypatch.setattr(bulk_build, "_tool_version", lambda sim: "Verilator 5.048")
    monkeypatch.setattr(bulk_build, "runners", lambda: {"verilator": _Runner, "icarus": _Runner})
    _Runner.builds = []
    unit, meta, _ = build_unit("sincos", Config())
    unit._MustUse__silence = True                        # built for its sidecar only
    v = tmp_path / "sincos.v"
    v.write_text("module sincos(); endmodule\n")
    saved = dict(os.environ)
    bdir, top, seconds, cached = build("verilator", v, meta, 64, cache=tmp_path / "cache")
    assert not cached and bdir.parent == tmp_path / "cache" and bdir.name.startswith("verilator-sincos-")
    assert (bdir / "sincos.v").read_text() == v.read_text() and (bdir / f"{top}.v").is_file()
    marker = json.loads((bdir / "bulk_build.json").read_text())
    assert marker["build_s"] == seconds and marker["make"] == ["OPT_FAST=-Os"]
    assert marker["args"] == build_args("verilator") and marker["top"] == top
    [b] = _Runner.builds
    assert b["main"] == MAIN_CPP and "OPT_FAST=-Os" in b["MAKEFLAGS"]   # during the build only
    assert b["hdl_toplevel"] == top and b["build_args"] == marker["args"]
    assert b["parameters"]["DEPTH"] == 64
    assert dict(os.environ) == saved
    again = build("verilator", v, meta, 64, cache=tmp_path / "cache")
    assert again == (bdir, top, seconds, True) and len(_Runner.builds) == 1
    other = build("verilator", v, meta, 64, cache=tmp_path / "cache", opt_fast="-O2")
    assert other[0] != bdir and not other[3] and len(_Runner.builds) == 2
    v.write_text("module sincos(); wire x; endmodule\n")               # another unit text
    assert build("verilator", v, meta, 64, cache=tmp_path / "cache")[0] not in (bdir, other[0])
    ic = build("icarus", v, meta, 64, cache=tmp_path / "cache")
    assert _Runner.builds[-1]["main"] is None and ic[0].name.startswith("icarus-sincos-")


def test_run_cocotb_refuses_an_unknown_simulator_before_any_build(tmp_path):
    from bumprtl.sim.tb.runner import run_cocotb
    with pytest.raises(ValueError, match="simulator must be one of icarus, verilator, got 'vcs'"):
        run_cocotb("vcs", tmp_path / "x.v", "bumprtl.sim.tb.tb_datapath", tmp_path / "b")
    assert list(tmp_path.iterdir()) == []
