"""The traffic patterns of every stream test, after verilog-axis: no stall, random input
gaps, random output backpressure, and both at once. One table for the Amaranth-simulator
helper (sim/amaranth_stream.py) and the cocotb testbenches (sim/tb/stream.py); no
simulator is imported here."""

__all__ = ["PATTERNS", "fill_hold"]

# name -> (probability of an input gap, probability of output backpressure)
PATTERNS = {"no_stall": (0.0, 0.0), "input_gaps": (0.4, 0.0), "backpressure": (0.0, 0.4),
            "both": (0.3, 0.3)}


def fill_hold(latency):
    """Cycles of the bulk wrapper's first stall (sim/tb/bulk_wrapper.v ``fill_hold``) for a
    unit of ``latency``, under every pattern with output backpressure: each chunk starts
    with o.ready low until i.ready has been low (every credit spent) or the chunk's input
    all taken for this many cycles, twice the latency and 8 more (a texel-cache miss's wait
    included), so that every pixel taken sits in the credit FIFO, full, before the random
    stalls drain it. Random stalls alone never fill it: the sink would have to stall for
    about a latency in a row."""
    return 2 * latency + 8
