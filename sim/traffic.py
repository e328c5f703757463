"""The traffic patterns of every stream test, after verilog-axis: no stall, random input
gaps, random output backpressure, and both at once. One table for the Amaranth-simulator
helper (sim/amaranth_stream.py) and the cocotb testbenches (sim/tb/stream.py); no
simulator is imported here."""

__all__ = ["PATTERNS"]

# name -> (probability of an input gap, probability of output backpressure)
PATTERNS = {"no_stall": (0.0, 0.0), "input_gaps": (0.4, 0.0), "backpressure": (0.0, 0.4),
            "both": (0.3, 0.3)}
