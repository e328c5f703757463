"""The board's units as targets of tests/mutants/netlist.py (``make mutate-rtl``): the video
timing (rtl/video.VideoTiming), one TMDS encoder lane (rtl/tmds.TMDSEncoder), the elastic
buffer (the pipeline's credit FIFO, rtl/pipe.CreditFIFO, at the board's width and depth)
and the pixel source (rtl/board.PixelSource), each emitted alone as the board builds it for
the default scene in the reduced mode ``test`` (rtl/video.MODES).

Each has a bench made for mutants: a seeded stimulus of a few thousand clock cycles (input
ports and the synchronous reset, with a reset pulse part way), run on Icarus through the
mutated netlist (netlist.py's shim, ``mutsel.txt``), every output sampled every cycle and
compared with an oracle that is not the RTL:

* ``board:timing``: the raster of the mode's numbers (x, y, de and the sync levels) counted
  here from the VESA-style line of rtl/video.MODES (active, porches, sync, polarity);
* ``board:tmds``: the DVI 1.0 encoding flow chart of tests/rtl/test_tmds.py (``dvi_encode``,
  written from the standard) with its control symbols, two cycles behind the inputs;
* ``board:buffer``: a first-in first-out queue as docs/architecture.md states the credit
  FIFO: every read returns the oldest unread word, ``level`` counts the unread words, a
  word can be read from the third cycle after its write on (EDGE_LATENCY, typed here as
  3); the writes come as the credits allow them (fewer than depth words unread), and
  ``w_rdy``, which the board never reads (the FIFO states it for the proofs), is not an
  output of the target;
* ``board:source``: the raster order of sim/golden/board.py's frames (texel coordinates by
  rtl/board.texel_coords, the plane's constants and a 4-step light table from
  plane_constants / light_table), one pixel a transfer, valid from the second cycle after
  reset, the light step advancing after each frame; the payload compared where valid is
  high (the stream contract), valid and the light step every cycle.

Every bench starts in reset (cycle 0, not compared: the board's reset synchronizer holds
the core in reset after the PLL locks). A mismatch kills a mutant; an x or z on an output is
a mismatch; a simulation that fails or
does not finish in its time is undecided (reason given).
"""

import functools
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
from harness_ports import Design

HERE = Path(__file__).resolve().parent
TARGETS = ("board:timing", "board:tmds", "board:buffer", "board:source")
UNIT = {"board:timing": "video_timing", "board:tmds": "tmds_encoder",
        "board:buffer": "elastic_buffer", "board:source": "pixel_source"}
MODE = "test"
LIGHT_STEPS = 4            # the source's light table: small, so that the step wraps
FIFO_DELAY = 3             # docs/architecture.md: written in cycle t, readable from t + 3
SIM_TIMEOUT = 120          # seconds for one mutant's simulation


class BenchError(Exception):
    """The bench could not be built (the message names the step)."""


# --- the units, emitted alone -------------------------------------------------------------

@functools.cache
def _default_scene():
    from bumprtl.rtl.pipeline import BumpPipeline
    from bumprtl.sim.scenes.config import load_scene_config
    scene = load_scene_config("default")
    # only its input stream and its numbers are used: the pipeline itself is not emitted
    warnings.filterwarnings("ignore", message=".*created but never used")
    return scene, BumpPipeline(scene.hardware)


def _leaves(layout, base=0, prefix=""):
    """(key, bit offset, width) of every leaf field of an Amaranth data layout."""
    from amaranth.lib import data
    for name, field in layout:
        shape = field.shape
        key = f"{prefix}{name}"
        if isinstance(shape, data.Layout):
            yield from _leaves(shape, base + field.offset, key + ".")
        else:
            yield key, base + field.offset, field.width


def _unit(target):
    """(elaboratable, [(port signal, "in"|"out")], context for the oracle)."""
    from amaranth.hdl import Elaboratable, Module, Signal

    from bumprtl.rtl.board import PixelSource, buffer_depth
    from bumprtl.rtl.tmds import TMDSEncoder
    from bumprtl.rtl.video import MODES, VideoTiming
    mode = MODES[MODE]
    if target == "board:timing":
        u = VideoTiming(mode)
        return u, [(u.x, "out"), (u.y, "out"), (u.de, "out"), (u.hsync, "out"),
                   (u.vsync, "out")], {"mode": mode}
    if target == "board:tmds":
        u = TMDSEncoder()
        return u, [(u.data, "in"), (u.de, "in"), (u.c0, "in"), (u.c1, "in"), (u.q, "out")], {}
    scene, pipe = _default_scene()
    if target == "board:buffer":
        width, depth = 24 + pipe.cfg.tag_bits, buffer_depth(pipe.latency)
        from bumprtl.rtl.pipe import CreditFIFO

        class Buffer(Elaboratable):
            """The FIFO with its ports named as amaranth.lib.fifo names them, those the
            board reads (not ``w_rdy``: the credits guarantee room, the FIFO states it for
            the proofs only)."""

            def __init__(self):
                self.fifo = CreditFIFO(width, depth)
                self.w_en, self.r_en = Signal(name="w_en"), Signal(name="r_en")
                self.w_data = Signal(width, name="w_data")
                self.r_rdy = Signal(name="r_rdy")
                self.r_data = Signal(width, name="r_data")
                self.level = Signal.like(self.fifo.level, name="level")

            def elaborate(self, platform):
                m = Module()
                m.submodules.fifo = f = self.fifo
                m.d.comb += [f.w_en.eq(self.w_en), f.w_data.eq(self.w_data), f.r_en.eq(self.r_en),
                             self.r_rdy.eq(f.r_rdy),
                             self.r_data.eq(f.r_data), self.level.eq(f.level)]
                return m

        u = Buffer()
        return u, [(u.w_en, "in"), (u.w_data, "in"), (u.r_en, "in"),
                   (u.r_rdy, "out"), (u.r_data, "out"), (u.level, "out")], \
            {"width": width, "depth": depth}
    from bumprtl.sim.golden.board import light_table, plane_constants
    constants, table = plane_constants(scene), light_table(scene, LIGHT_STEPS)
    src = PixelSource(pipe, mode, constants, table)
    layout = pipe.i.payload.shape()

    class Unit(Elaboratable):
        def __init__(self):
            self.allow = Signal(name="allow")
            self.ready = Signal(name="o__ready")
            self.valid = Signal(name="o__valid")
            self.payload = Signal(layout.size, name="o__payload")
            self.step = Signal(len(src.frame), name="light_step")

        def elaborate(self, platform):
            m = Module()
            m.submodules.source = src
            m.d.comb += [src.allow.eq(self.allow), pipe.i.ready.eq(self.ready),
                         self.valid.eq(pipe.i.valid), self.payload.eq(pipe.i.payload.as_value()),
                         self.step.eq(src.frame)]
            return m
    u = Unit()
    return u, [(u.allow, "in"), (u.ready, "in"), (u.valid, "out"), (u.payload, "out"),
               (u.step, "out")], {"mode": mode, "constants": constants, "table": table,
                                  "leaves": list(_leaves(layout)), "size": scene.texture_size,
                                  "tag_bits": pipe.cfg.tag_bits}


def emit(target, out):
    """Emit ``target``'s Verilog into ``out``: (path, Design, context), the
    :class:`harness_ports.Design` of the module's ports with clk and rst (a board unit
    emitted alone has no sidecar: netlist.py keeps the Design in its run directory)."""
    from amaranth.back import verilog
    unit = UNIT[target]
    u, ports, ctx = _unit(target)
    out.mkdir(parents=True, exist_ok=True)
    text = verilog.convert(u, name=unit, ports=[s for s, _ in ports], emit_src=False)
    path = out / f"{unit}.v"
    path.write_text(text)
    return path, Design.from_signals(unit, ports), ctx


# --- stimulus and oracles ------------------------------------------------------------------

def _reset_at(rng, n):
    """The reset: high in cycle 0 (as the board's reset synchronizer holds it after the PLL
    locks; the outputs of cycle 0 are not compared, see Bench.run) and in a pulse somewhere
    in the middle third of ``n`` cycles."""
    rst = np.zeros(n, np.int64)
    rst[0] = 1
    t = int(rng.integers(n // 3, 2 * n // 3))
    rst[t:t + int(rng.integers(1, 4))] = 1
    return rst


def _timing(ctx, rng):
    md = ctx["mode"]
    n = 2 * md.frame_clocks + md.h_total
    ins = {"rst": _reset_at(rng, n)}
    x, y = 0, md.v_active
    hs0, vs0 = md.h_active + md.h_front, md.v_active + md.v_front
    exp = {k: [] for k in ("x", "y", "de", "hsync", "vsync")}
    for t in range(n):
        exp["x"].append(x)
        exp["y"].append(y)
        exp["de"].append(int(x < md.h_active and y < md.v_active))
        exp["hsync"].append(int(hs0 <= x < hs0 + md.h_sync) ^ int(md.h_negative))
        exp["vsync"].append(int(vs0 <= y < vs0 + md.v_sync) ^ int(md.v_negative))
        if ins["rst"][t]:
            x, y = 0, md.v_active
        elif x == md.h_total - 1:
            x, y = 0, (0 if y == md.v_total - 1 else y + 1)
        else:
            x += 1
    return ins, exp, {}


@functools.cache
def _dvi():
    """tests/rtl/test_tmds.py's flow chart of DVI 1.0 (dvi_encode, CONTROL_SYMBOLS)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("_dvi_flow_chart",
                                                  HERE.parent / "rtl" / "test_tmds.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.dvi_encode, mod.CONTROL_SYMBOLS


def _tmds(ctx, rng):
    encode, control = _dvi()
    n = 6000
    de = np.zeros(n, np.int64)
    t = 0
    while t < n:                      # active runs and blanking runs of random lengths
        run = int(rng.integers(1, 200))
        de[t:t + run] = int(rng.random() < 0.7)
        t += run
    data = rng.integers(0, 256, n)
    # stretches of few or many ones drive the disparity to its ends
    for _ in range(20):
        s = int(rng.integers(0, n - 60))
        data[s:s + 60] = rng.choice([0x00, 0x01, 0x80, 0xFF, 0xFE, 0x7F, 0x10, 0xEF], 60)
    ins = {"data": data, "de": de, "c0": rng.integers(0, 2, n), "c1": rng.integers(0, 2, n),
           "rst": _reset_at(rng, n)}
    q, cnt = control[(0, 0)], 0
    stage = (0, 0, 0, 0)              # (data, de, c0, c1) registered: the init values
    exp = []
    for t in range(n):
        exp.append(q)
        if ins["rst"][t]:
            q, cnt, stage = control[(0, 0)], 0, (0, 0, 0, 0)
            continue
        d, e, c0, c1 = stage
        if e:
            q, cnt = encode(cnt, d)
        else:
            q, cnt = control[(c1, c0)], 0
        stage = tuple(int(ins[k][t]) for k in ("data", "de", "c0", "c1"))
    return ins, {"q": exp}, {}


def _buffer(ctx, rng):
    depth, width = ctx["depth"], ctx["width"]
    n = 3000
    # phases: filling (writes often, reads rarely), draining, balanced
    p_w, p_r = np.empty(n), np.empty(n)
    for k, t in enumerate(range(0, n, 250)):
        p_w[t:t + 250], p_r[t:t + 250] = [(0.9, 0.1), (0.1, 0.9), (0.6, 0.6)][k % 3]
    ins = {"w_en": (rng.random(n) < p_w).astype(np.int64),
           "r_en": (rng.random(n) < p_r).astype(np.int64),
           "w_data": rng.integers(0, 1 << width, n, dtype=np.int64),
           "rst": _reset_at(rng, n)}
    queue = []                        # unread words: (word, the cycle it was written)
    exp = {k: [] for k in ("r_rdy", "r_data", "level")}
    care = {"r_data": []}
    for t in range(n):
        if len(queue) >= depth:       # no credit free: the pipeline writes nothing
            ins["w_en"][t] = 0
        r_rdy = int(bool(queue) and queue[0][1] <= t - FIFO_DELAY)
        level = len(queue)
        exp["r_rdy"].append(r_rdy)
        exp["level"].append(level)
        exp["r_data"].append(queue[0][0] if r_rdy else 0)
        care["r_data"].append(r_rdy)
        if ins["rst"][t]:
            queue = []
            continue
        if r_rdy and ins["r_en"][t]:
            queue.pop(0)
        if ins["w_en"][t]:
            queue.append((int(ins["w_data"][t]), t))
    return ins, exp, care


def _source(ctx, rng):
    from bumprtl.rtl.board import texel_coords
    md, table, fields = ctx["mode"], ctx["table"], ctx["leaves"]
    # two frames a light step, and past the tag's wrap: the tag counts the pixels issued
    # (allow and ready each 0.8 of the cycles), so its top bits are reached only after
    # 2**(tag_bits - 1) of them
    n = max(int(2.0 * md.pixels * (LIGHT_STEPS + 1)), int(1.25 * (1 << ctx["tag_bits"]) / 0.64))
    ins = {"allow": (rng.random(n) < 0.8).astype(np.int64),
           "o__ready": (rng.random(n) < 0.8).astype(np.int64), "rst": _reset_at(rng, n)}
    ins["rst"][1:] = 0                # a reset part way would need one more frame wrap:
    ins["rst"][n // 5:n // 5 + 2] = 1  # early, so that the step still wraps after it
    px = py = frame = count = primed = 0
    mask = (1 << ctx["tag_bits"]) - 1
    exp = {"o__valid": [], "o__payload": [], "light_step": []}
    care = {"o__payload": []}
    for t in range(n):
        valid = int(ins["allow"][t] and primed)
        u, v = texel_coords(px, py, md.zoom, ctx["size"])
        value = {"u": u, "v": v, "tag": count, **ctx["constants"], **table[frame]}
        word = 0
        for key, off, width in fields:
            word |= (int(value.get(key, 0)) & ((1 << width) - 1)) << off
        exp["o__valid"].append(valid)
        exp["o__payload"].append(word)
        exp["light_step"].append(frame)
        care["o__payload"].append(valid)
        if ins["rst"][t]:
            px = py = frame = count = primed = 0
            continue
        primed = 1
        if valid and ins["o__ready"][t]:
            last_x, last_y = px == md.h_active - 1, py == md.v_active - 1
            if last_x and last_y:
                frame = (frame + 1) % len(table)
            px = 0 if last_x else px + 1
            if last_x:
                py = 0 if last_y else py + 1
            count = (count + 1) & mask
    return ins, exp, care


ORACLE = {"board:timing": _timing, "board:tmds": _tmds, "board:buffer": _buffer,
          "board:source": _source}


# --- the bench: one Icarus build of the mutated netlist, one run a mutant -------------------

class Bench:
    """The stimulus and expected outputs of ``target`` (seeded), a Verilog testbench that
    drives the stimulus cycle by cycle and writes every output each cycle, built once with
    the mutated netlist; :meth:`run` runs it with ``mutsel`` = idx."""

    def __init__(self, target, design, ctx, seed):
        self.target, self.design = target, design
        rng = np.random.default_rng(seed)
        self.inputs, self.expected, self.care = ORACLE[target](ctx, rng)
        self.ins = [p for p in design.names("in") if p != "clk"]
        self.outs = design.names("out")
        self.cycles = len(next(iter(self.inputs.values())))
        self.words = (f"{self.cycles} cycles of seeded stimulus (seed {seed}) with a reset "
                      f"pulse, every output compared each cycle with {_ORACLE_WORDS[target]}, "
                      f"on Icarus")

    def testbench(self):
        ports = self.design.ports
        width = sum(ports[p].width for p in self.ins)
        regs = "\n".join(f"  reg [{ports[p].width - 1}:0] {p};" for p in self.ins)
        wires = "\n".join(f"  wire [{ports[p].width - 1}:0] {p};" for p in self.outs)
        conn = ", ".join(f".{p}({p})" for p in ["clk", *self.ins, *self.outs])
        fmt = " ".join("%h" for _ in self.outs)
        return f"""`timescale 1ns/1ps
module bench;
  reg clk = 0;
{regs}
{wires}
  reg [{width - 1}:0] stim [0:{self.cycles - 1}];
  integer t, fd;
  {self.design.module} dut({conn});
  initial begin
    $readmemh("stim.hex", stim);
    fd = $fopen("outputs.txt", "w");
    for (t = 0; t < {self.cycles}; t = t + 1) begin
      {{{', '.join(self.ins)}}} = stim[t];
      #2 $fdisplay(fd, "{fmt}", {', '.join(self.outs)});
      #3 clk = 1;
      #5 clk = 0;
    end
    $fclose(fd);
    $finish;
  end
endmodule
"""

    def build(self, mutated, work):
        """Icarus: the mutated netlist and the testbench into ``work``/bench.vvp."""
        ports = self.design.ports
        (work / "bench.v").write_text(self.testbench())
        hexw = (sum(ports[p].width for p in self.ins) + 3) // 4
        lines = []
        for t in range(self.cycles):
            word = 0
            for p in self.ins:
                word = (word << ports[p].width) | int(self.inputs[p][t])
            lines.append(f"{word:0{hexw}x}")
        (work / "stim.hex").write_text("\n".join(lines) + "\n")
        iverilog = shutil.which("iverilog")
        if not iverilog:
            raise BenchError("iverilog not found (make icarus installs it)")
        r = subprocess.run([iverilog, "-g2012", "-o", "bench.vvp", "-s", "bench", "bench.v",
                            str(Path(mutated).resolve())], cwd=work, capture_output=True,
                           text=True)
        if r.returncode:
            raise BenchError(f"iverilog: {(r.stderr or r.stdout).strip().splitlines()[:1]}")
        self.vvp = (work / "bench.vvp").resolve()
        self.stim = (work / "stim.hex").resolve()

    def run(self, work, idx):
        """``"passed"``, ``"killed: <output> at cycle <t>: <got> != <want>"`` or
        ``"undecided: simulation: ..."``."""
        work.mkdir(parents=True, exist_ok=True)
        (work / "mutsel.txt").write_text(f"{idx}\n")
        shutil.copy(self.stim, work / "stim.hex")
        try:
            r = subprocess.run([shutil.which("vvp") or "vvp", "-n", str(self.vvp)], cwd=work,
                               capture_output=True, text=True, timeout=SIM_TIMEOUT)
        except subprocess.TimeoutExpired:
            return f"undecided: simulation: no end within {SIM_TIMEOUT} s"
        path = work / "outputs.txt"
        if r.returncode or not path.exists():
            said = (r.stderr or r.stdout).strip().splitlines()[-1:] or [f"exit {r.returncode}"]
            return f"undecided: simulation: vvp: {said[0][:120]}"
        rows = path.read_text().split("\n")
        # from cycle 1 on: cycle 0 shows the initial values, and a mutation of a register's
        # Q leaves the new wire's initial value undefined in the netlist (x on Icarus) where
        # the board's first reset defines it
        for t in range(1, self.cycles):
            got = rows[t].split() if t < len(rows) else []
            if len(got) != len(self.outs):
                return f"killed: cycle {t}: {len(got)} outputs written, not {len(self.outs)}"
            for p, g in zip(self.outs, got, strict=True):
                if self.care.get(p) is not None and not self.care[p][t]:
                    continue
                want = int(self.expected[p][t])
                if any(c in g.lower() for c in "xz"):
                    return f"killed: {p} is {g} at cycle {t}, want {want:x}"
                if int(g, 16) != want:
                    return f"killed: {p} at cycle {t}: {int(g, 16):x} != {want:x}"
        return "passed"


_ORACLE_WORDS = {
    "board:timing": "the raster counted from the mode's numbers",
    "board:tmds": "the DVI 1.0 flow chart (tests/rtl/test_tmds.py's dvi_encode)",
    "board:buffer": "a FIFO queue with the credit FIFO's stated latency and level",
    "board:source": "the golden board frames' raster order and light table "
                    "(sim/golden/board.py), payload where valid",
}


def bench(target, rtl, seed):
    """Emit ``target`` into ``rtl``: (Verilog path, Design, Bench)."""
    v, design, ctx = emit(target, rtl)
    return v, design, Bench(target, design, ctx, seed)


if __name__ == "__main__":
    print("run through tests/mutants/netlist.py -k board:...", file=sys.stderr)
    sys.exit(2)
