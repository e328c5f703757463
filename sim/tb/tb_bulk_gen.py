"""cocotb side of the bulk path for generated stimulus (sim/tb/bulk_sources.py): the
regressions' 10^7 vectors are made and checked chunk by chunk in the simulator process.
The same harness as sim/tb/tb_bulk.py; a module of its own so that a render, which
brings its arrays, does not import the golden models and Amaranth at start-up."""

import cocotb

from bumprtl.sim.tb.bulk_sources import make_source
from bumprtl.sim.tb.tb_bulk import run_job


@cocotb.test()
async def bulk_generated(dut):
    await run_job(dut, make_source)
