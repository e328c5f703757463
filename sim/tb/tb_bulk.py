"""cocotb side of the bulk path (sim/tb/bulk.py, wrapper sim/tb/bulk_wrapper.v): stream chunks of stimulus through the
bulk wrapper and compare the outputs with the golden model.

Per chunk it writes ``bulk_in.bin``, sets the count, the traffic seeds and densities,
raises ``start`` and sleeps (a cocotb Timer) until ``done``: the clock runs inside the
simulator meanwhile, and Python wakes up a few times per chunk, never per clock. Then it
reads ``bulk_out.bin`` back as arrays and checks them: every tag once and in order, and
every field bit for bit against the golden outputs when the source has them. With an AXI
memory in the wrapper (a ``map_memory = "axi"`` unit) it sets the memory's latency from the
job and counts, per pattern, the AR requests and the sum of their addresses.

Environment: BUMPRTL_BULK_JOB, the job JSON that :func:`bumprtl.sim.tb.bulk.run_bulk`
writes (sidecar, patterns, traffic, set-up cycles, source, result and summary paths). The
summary JSON (pixels, cycles and seconds per pattern, or the error) is written even when
the test fails, so the caller can raise with the message.
"""

import json
import os
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import Timer

from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.tb.bulk_codec import decode_words, encode_words
from bumprtl.sim.tb.bulk_wrapper import (
    DENSITY_BITS,
    IN_FILE,
    OUT_FILE,
    PERIOD,
    SETUP_FILE,
    host_fields,
    reset_prefix,
    setup_arrays,
)
from bumprtl.sim.traffic import fill_hold

DENSITY_ONE = 1 << DENSITY_BITS

# A guard in case the wrapper itself never raises done (its idle limit ends a deadlock):
# clock cycles per pixel, and fixed.
GUARD_CYCLES_PER_PIXEL = 1000
GUARD_CYCLES = 1 << 20


def _seed(base, chunk, pattern, which):
    """Distinct non-zero 32-bit xorshift seeds per chunk, pattern and generator."""
    x = (base * 0x9E3779B1 + chunk * 0x85EBCA77 + pattern * 0xC2B2AE3D + which * 0x27D4EB2F)
    return (x & 0xFFFFFFFF) or 1


async def _cycle(n=1):
    """``n`` clock periods: cocotb acts half a period after a rising edge, never on one."""
    await Timer(PERIOD * n, "ns")


async def _reset_and_setup(dut, meta, setup, chunk):
    """Reset, junk pixels in flight and a reset again (the wrapper's reset prefix), then the
    host set-up cycles (``[{port: int}]``, one per clock), played by the
    wrapper from ``bulk_setup.bin`` in chunks: a map written through its port costs one
    clock a word, not one cocotb wake-up."""
    dut.start.value = 0
    dut.count.value = 0
    dut.setup_mode.value = 0
    dut.rst.value = 1
    await Timer(PERIOD // 2, "ns")
    await _cycle(4)
    dut.rst.value = 0
    await _cycle(2)
    # junk pixels in flight, then a reset (bulk_wrapper.reset_prefix): none may come out
    dut.reset_prefix.value = reset_prefix(meta)
    dut.fill_hold.value = 0
    dut.start.value = 1
    if not await _wait_done(dut, reset_prefix(meta), 0, 0):
        raise AssertionError("timeout: the wrapper never finished the reset prefix")
    dut.start.value = 0
    while int(dut.done.value):
        await _cycle()
    dut.reset_prefix.value = 0
    await _host_cycles(dut, meta, setup, chunk)


async def _host_cycles(dut, meta, setup, chunk):
    """Host cycles (``[{port: int}]``, one per clock) played by the wrapper from
    ``bulk_setup.bin`` in chunks, with no pixel in flight."""
    if not setup:
        return
    fields, width = host_fields(meta)
    words = setup_arrays(meta, setup)
    dut.setup_mode.value = 1
    for s in range(0, len(setup), chunk):
        part = {k: v[s:s + chunk] for k, v in words.items()}
        n = len(next(iter(part.values())))
        Path(SETUP_FILE).write_bytes(encode_words(fields, width, part))
        dut.count.value = n
        dut.start.value = 1
        if not await _wait_done(dut, n, 0, 0):
            raise AssertionError(f"timeout: the wrapper never finished {n} set-up cycles")
        dut.start.value = 0
        while int(dut.done.value):
            await _cycle()
    dut.setup_mode.value = 0
    await _cycle(2)


async def _wait_done(dut, n, gap, stall):
    """Sleep until the wrapper raises done: first for the cycles the chunk should take,
    then for the cycles its remaining pixels should take. The wrapper's clock stops at
    done, so an overshoot costs no simulation. Returns False when the guard expired."""
    rate = max((1 - gap / DENSITY_ONE) * (1 - stall / DENSITY_ONE), 1 / 64)
    waited, guard = 0, GUARD_CYCLES + GUARD_CYCLES_PER_PIXEL * n
    step = int(n / rate) + 64
    while waited < guard:
        await _cycle(step)
        waited += step
        if int(dut.done.value):
            return True
        step = max(int((n - int(dut.n_out.value)) / rate), 256)
    return False


def _compare(pattern, k, got, want, inputs):
    for name, w in want.items():
        g = got[name]
        bad = np.nonzero(g != w)[0]
        if bad.size:
            i = int(bad[0])
            raise AssertionError(
                f"pattern {pattern}, chunk {k}: output {i} field {name}: RTL {int(g[i])} != "
                f"golden {int(w[i])} (tag {int(inputs['tag'][i])}; {bad.size} of {len(w)} "
                f"differ in this field)")


async def _run(dut, job, meta, summary, make_source):
    fin, fout = meta.input_fields, meta.output_fields
    iw, ow = meta.port("i__payload").width, meta.port("o__payload").width
    patterns = job["patterns"]
    setup, chunks = make_source(meta, job["source"], job["chunk"])
    axi = job.get("axi_latency") is not None
    if axi:
        dut.axi_latency.value = job["axi_latency"]
    await _reset_and_setup(dut, meta, job["setup"] + setup, job["chunk"])
    dut.idle_limit.value = job["idle_limit"]
    kept = {p: [] for p in patterns}
    stats = summary["patterns"]
    for k, (inputs, expected) in enumerate(chunks):
        n = len(inputs["tag"])
        Path(IN_FILE).write_bytes(encode_words(fin, iw, inputs))
        for j, pattern in enumerate(patterns):
            if k or j:               # every run but the first: the job's host cycles between
                await _host_cycles(dut, meta, job.get("between", []), job["chunk"])
            gap, stall = job["traffic"][pattern]
            dut.gap_density.value, dut.bp_density.value = gap, stall
            dut.fill_hold.value = fill_hold(meta.latency) if stall else 0
            dut.gap_seed.value = _seed(job["seed"], k, j, 0)
            dut.bp_seed.value = _seed(job["seed"], k, j, 1)
            dut.count.value = n
            ars = (int(dut.ar_count.value), int(dut.ar_sum.value)) if axi else None
            dut.start.value = 1
            t0, c0 = time.perf_counter(), time.process_time()
            if not await _wait_done(dut, n, gap, stall):
                summary["timeout"] = True
                raise AssertionError(
                    f"timeout: the wrapper never finished pattern {pattern} chunk {k}: "
                    f"{stats[pattern]['pixels'] + int(dut.n_in.value)} pixels went in, "
                    f"{stats[pattern]['pixels'] + int(dut.n_out.value)} came out of "
                    f"{stats[pattern]['pixels'] + n}") from None
            s = stats[pattern]
            s["sim_s"] += time.perf_counter() - t0
            s["sim_cpu_s"] += time.process_time() - c0
            n_in, n_out, cycles = int(dut.n_in.value), int(dut.n_out.value), int(dut.cycles.value)
            dut.start.value = 0
            if int(dut.timed_out.value):
                summary["timeout"] = True
                raise AssertionError(
                    f"timeout (deadlock): pattern {pattern}: {s['pixels'] + n_in} pixels went "
                    f"in, {s['pixels'] + n_out} came out of {s['pixels'] + n} "
                    f"(chunk {k}: {n_in} in, {n_out} out of {n}); no output for "
                    f"{job['idle_limit']} cycles, {cycles} cycles in the chunk")
            while int(dut.done.value):           # the wrapper clears done at the next edge
                await _cycle()
            got = decode_words(fout, ow, Path(OUT_FILE).read_bytes())
            assert len(got["tag"]) == n, \
                f"pattern {pattern} chunk {k}: {len(got['tag'])} words in {OUT_FILE}, {n} expected"
            _compare(pattern, k, got, {"tag": inputs["tag"]}, inputs)      # each once, in order
            if expected is not None:
                _compare(pattern, k, got, expected, inputs)
                summary["checked"] = True
            s["pixels"] += n
            s["cycles"] += cycles
            if axi:
                s["ar"] = s.get("ar", 0) + int(dut.ar_count.value) - ars[0]
                s["ar_sum"] = s.get("ar_sum", 0) + int(dut.ar_sum.value) - ars[1]
            if job["keep"]:
                kept[pattern].append(got)
        dut._log.info("chunk %d: %d pixels x %d patterns", k, n, len(patterns))
    if job["keep"]:
        result = {}
        for p in patterns:
            for name in fout:
                result[f"{p}.{name}"] = (np.concatenate([g[name] for g in kept[p]]) if kept[p]
                                         else np.zeros(0, np.int64))
        np.savez(job["result"], **result)


def array_source(meta, spec, chunk):
    """The stimulus (and golden outputs, if any) from an npz: ``in.<field>``,
    ``expect.<field>``; no set-up of its own (the job's ``setup`` cycles drive the host ports)."""
    data = np.load(spec["path"])
    ins = {k[3:]: data[k] for k in data.files if k.startswith("in.")}
    exp = {k[7:]: data[k] for k in data.files if k.startswith("expect.")}
    n = len(next(iter(ins.values())))

    def chunks():
        for s in range(0, n, chunk):
            yield ({k: v[s:s + chunk] for k, v in ins.items()},
                   {k: v[s:s + chunk] for k, v in exp.items()} or None)
    return [], chunks()


async def run_job(dut, make_source):
    """The whole job of BUMPRTL_BULK_JOB: reset, set-up, every chunk under every pattern.
    ``make_source(meta, spec, chunk)`` -> ``(setup cycles, iterator of (inputs, expected))``.
    The summary JSON is written whatever happens."""
    job = json.loads(Path(os.environ["BUMPRTL_BULK_JOB"]).read_text())
    meta = load_sidecar(job["sidecar"])
    summary = {"patterns": {p: {"pixels": 0, "cycles": 0, "sim_s": 0.0, "sim_cpu_s": 0.0}
                            for p in job["patterns"]},
               "finished": False, "checked": False, "timeout": False, "error": None}
    try:
        await _run(dut, job, meta, summary, make_source)
        summary["finished"] = True
    except AssertionError as e:
        summary["error"] = str(e)
        raise
    finally:
        Path(job["summary"]).write_text(json.dumps(summary, indent=1) + "\n")


@cocotb.test()
async def bulk_stream(dut):
    """Stimulus arrays from the job's npz (the render, the small tests)."""
    await run_job(dut, array_source)
