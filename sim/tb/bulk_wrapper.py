"""The bulk wrapper (sim/tb/bulk_wrapper.v) filled in for one emitted unit from its JSON
sidecar, and the host set-up words it plays into the unit's host ports.

The wrapper is a Verilog file with parameters (the payload widths, the chunk depth, the
host word's width, the clock period), the unit's module name as the macro ``BULK_UNIT``
and one text hook: the host-port connections of the unit instance. Simulation only
(``$fread``, ``$fwrite``, delays); never synthesised.

Control (cocotb, between chunks): ``rst``; ``start`` (level) with ``count`` words in
``bulk_in.bin``, or with ``setup_mode`` set ``count`` set-up words in ``bulk_setup.bin``,
played one per clock into the host ports; ``gap_seed``/``gap_density``,
``bp_seed``/``bp_density`` (a gap or a stall when the upper 16 bits of the next xorshift32
state are below the density, out of 2**16); ``fill_hold`` (non-zero: the chunk's first
stall, o.ready low until i.ready has been low or the input all taken for that many
cycles, sim/traffic.fill_hold); ``reset_prefix`` (non-zero: the run begins with that
many cycles of junk pixels offered to a stalled sink, then a one-cycle reset of the unit
with them in flight; with ``count`` 0 that is the whole run, :func:`reset_prefix`);
``idle_limit``. Status: ``done`` (held until ``start`` falls), ``timed_out``, ``n_in``,
``n_out``, ``cycles``. Outputs go to ``bulk_out.bin``, one ``%u`` word each. A unit with an AXI4 read port (``axi__*``,
``map_memory = "axi"``) gets the wrapper's memory model on it (``BULK_AXI``): it holds
``bulk_axi.bin`` (:data:`AXI_FILE`, the unit's ``_map.bin``), answers each burst
``axi_latency`` cycles after its AR handshake, and counts the requests (``ar_count``,
``ar_sum``).
"""

from importlib.resources import files

import numpy as np

from bumprtl.rtl.layouts import pack

__all__ = ["TEMPLATE", "TOP", "HOOK", "PERIOD", "DENSITY_BITS", "IN_FILE", "OUT_FILE",
           "SETUP_FILE", "AXI_FILE", "OWN_CLOCK_DEFINE", "AXI_DEFINE", "has_axi", "host_fields",
           "setup_arrays", "setup_writes", "wrapper_verilog", "reset_prefix"]

TEMPLATE = files("bumprtl.sim.tb").joinpath("bulk_wrapper.v")
TOP = "bulk_wrapper"
HOOK = "/*@host_ports@*/"
PERIOD = 10                             # the wrapper's own clock (Icarus), in ns
DENSITY_BITS = 16                       # a gap / stall when 16 LFSR bits < density
IN_FILE, OUT_FILE, SETUP_FILE = "bulk_in.bin", "bulk_out.bin", "bulk_setup.bin"
AXI_FILE = "bulk_axi.bin"
OWN_CLOCK_DEFINE = "BULK_OWN_CLOCK"
AXI_DEFINE = "BULK_AXI"
AXI_PREFIX = "axi__"                    # the unit's AXI4 read port (rtl/cache.py)
STREAM_PORTS = ("clk", "rst", "i__valid", "i__payload", "i__ready", "o__valid", "o__payload",
                "o__ready")


def _host_ports(meta):
    """The unit's inputs besides the two streams, clk, rst and the AXI port (map/LUT/polygon
    host ports), in name order: the wrapper registers the set-up word on its way into them."""
    return {name: p.width for name, p in sorted(meta.ports.items())
            if p.dir == "in" and name not in STREAM_PORTS and not name.startswith(AXI_PREFIX)}


def _other_outputs(meta):
    return {name: p.width for name, p in sorted(meta.ports.items())
            if p.dir == "out" and name not in STREAM_PORTS and not name.startswith(AXI_PREFIX)}


def has_axi(meta):
    """The unit has an AXI4 read port (its map in the user's memory)."""
    return any(name.startswith(AXI_PREFIX) for name in meta.ports)


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


def setup_writes(meta, polygon=None, table=None):
    """Host set-up cycles of a pipeline (cocotb drives them after reset, before the stream):
    the polygon registers of a flat map and the palette colour table (written, then
    swapped in). A list of ``{port: int}``, one per clock."""
    ports, cycles = meta.ports, []
    if polygon is not None and "poly" in ports:
        cycles.append({"poly": pack(meta.fields_of("poly"), polygon), "poly_en": 1})
    if table is not None and "lut_w_en" in ports:
        cycles += [{"lut_w_en": 1, "lut_w_addr": a, "lut_w_data": int(w)}
                   for a, w in enumerate(np.asarray(table).tolist())]
        cycles.append({"lut_swap": 1})
    return cycles


def _connections(meta):
    """The hook's text: each host port on its slice of the registered set-up word, each
    other output (e.g. the palette's bank) on its slice of the unread wire."""
    fields, _ = host_fields(meta)
    out, start = [], {}
    for name, (off, w, _s) in fields.items():
        port = name.split("#")[0]
        lo, hi = start.get(port, (off, off))
        start[port] = (min(lo, off), max(hi, off + w))
    for port, (lo, hi) in start.items():
        out.append(f".{port}(host_q[{hi - 1}:{lo}])")
    lo = 0
    for port, w in _other_outputs(meta).items():
        out.append(f".{port}(unread[{lo + w - 1}:{lo}])")
        lo += w
    out += [f".{name}(ax_{name[len(AXI_PREFIX):]})" for name in sorted(meta.ports)
            if name.startswith(AXI_PREFIX)]
    return "".join(f",\n    {c}" for c in out)


def wrapper_verilog(meta, own_clock, chunk):
    """The wrapper around the unit of sidecar ``meta``: ``(top, text, parameters,
    defines)``, the text being sim/tb/bulk_wrapper.v with its host-port hook filled in and
    a first line naming the unit; ``parameters`` and ``defines`` go to the simulator's
    build. ``own_clock``: the wrapper toggles ``clk`` (Icarus), else ``clk`` is an input
    (the C++ main of the Verilator build, bulk_main.cpp)."""
    template = TEMPLATE.read_text()
    if template.count(HOOK) != 1:
        raise AssertionError(f"{TEMPLATE}: expected one {HOOK} hook")
    unit = meta.unit
    _, hw = host_fields(meta)
    parameters = {"IW": meta.port("i__payload").width,
                  "OW": meta.port("o__payload").width, "DEPTH": chunk, "HW": hw,
                  "XW": sum(_other_outputs(meta).values()), "PERIOD": PERIOD}
    defines = {"BULK_UNIT": unit, **({OWN_CLOCK_DEFINE: 1} if own_clock else {})}
    if has_axi(meta):                   # the memory model and its image's place
        image = meta.memory_images["map"]
        parameters.update({"AXI_DW": meta.port("axi__rdata").width,
                           "AXI_AW": meta.port("axi__araddr").width,
                           "AXI_BYTES": 1 << (image["bytes"] - 1).bit_length(),
                           "AXI_BASE": image["base"]})
        defines[AXI_DEFINE] = 1
    head = f"// bulk wrapper around `{unit}` (widths from {unit}.json): {parameters}\n"
    return TOP, head + template.replace(HOOK, _connections(meta)), parameters, defines


def reset_prefix(meta):
    """The junk cycles of the run before the set-up (``reset_prefix`` of the wrapper, with
    ``count`` = 0) for the unit of sidecar ``meta``: its latency + 2, so every stage of the
    pipe holds a pixel and the FIFO has begun to fill when the unit is reset; after the
    reset no pixel may be in flight (docs/integration.md, Clock and reset), so any that
    comes out later is an output the golden model does not have. It runs before the host's
    set-up because a reset clears the host's registers (a flat map's polygon, the palette's
    bank in front), not the memories; an AXI memory drops its outstanding bursts with it."""
    return meta.latency + 2
