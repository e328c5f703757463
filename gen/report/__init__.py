"""Generated pages: Table 1, the FPGA report, timing, integration, recommend (their marked
sections and ``Made at:`` record: gen/tools/docs.py)."""
