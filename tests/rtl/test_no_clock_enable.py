"""No clock enable on any datapath register, product or block RAM (rtl/pipe.py): the
pipes are free-running and flow control lives in the credit edge.

Each design is elaborated to RTLIL and read by Yosys (``proc; flatten; opt``: Yosys turns
every register whose next value keeps its own value under some condition into a flip-flop
with an enable, ``$dffe``/``$sdffe``/...), and the netlist is read cell by cell:

* generic form (what ``bumprtl emit`` writes): every flip-flop with an enable belongs to
  the credit edge (``edge.``: credits and FIFO) or is one of the host-written registers
  named in :data:`HOST_REGISTERS`; every memory read port outside the edge is enabled by
  the constant 1;
* ECP5 form (what ``report fpga`` places): every DP16KD's CE/OCE and every MULT18X18D's
  CE pin is the constant 1 (a RAM's write port writes through WE alone).

Every unit of every method, and every built-in scene's pipeline: ``make test`` the paper's
method and the default scene, ``make regress`` the rest.
"""

import json

import pytest
from amaranth.back import rtlil

from bumprtl.gen.flow.units import build_unit
from bumprtl.gen.tools.yosys import run_yosys
from bumprtl.rtl.config import Config
from bumprtl.rtl.methods import METHODS
from bumprtl.rtl.pipe import ECP5
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

ENABLED_FF = {"$dffe", "$sdffe", "$adffe", "$aldffe", "$sdffce", "$dffsre", "$dlatch"}

# Registers the host writes through a port of its own, not pixels: the polygon registers
# (flat map, written once per polygon) and the palette's front-bank bit (flipped by swap).
HOST_REGISTERS = ("polygon", "palette.front", "front")

# make test reads the default scene's pipeline and the paper's method's units (with the
# shared sincos, palette and fetch); every other scene and method runs in make regress
# (each netlist takes Yosys 10-60 s).
QUICK_SCENE, QUICK_METHOD = "default", "exact"


def _regress_unless(quick):
    return () if quick else (pytest.mark.regress,)


SCENES = [pytest.param(s, marks=_regress_unless(s == QUICK_SCENE)) for s in sorted(BUILTIN)]
UNITS = [("sincos", None), ("palette", None), ("fetch", None),
         *[(kind, method) for method in sorted(METHODS) for kind in ("rotation", "illumination")]]
UNIT_PARAMS = [pytest.param(k, m, id=f"{k}-{m}" if m else k,
                            marks=_regress_unless(m in (None, QUICK_METHOD)))
               for k, m in UNITS]
PLACED = [pytest.param(m, marks=_regress_unless(m == QUICK_METHOD))
          for m in sorted(m for m in METHODS if METHODS[m].not_placed is None)]


def netlist(design, name, work):
    """The design's flattened, optimised Yosys netlist (write_json) as a dict."""
    work.mkdir(parents=True, exist_ok=True)
    (work / f"{name}.il").write_text(rtlil.convert(design, name=name, emit_src=False))
    run_yosys(f"read_rtlil {name}.il; hierarchy -top {name}; proc; flatten; opt; "
              f"write_json {name}.json", f"{name}.log", work)
    return json.loads((work / f"{name}.json").read_text())["modules"][name]


def _names(module):
    """net bit -> the net names carrying it (public names only)."""
    out = {}
    for name, net in module["netnames"].items():
        if not name.startswith("$"):
            for bit in net["bits"]:
                out.setdefault(bit, []).append(name)
    return out


def enabled_registers(module):
    """Every flip-flop with an enable, as the sorted public names of the nets on its Q."""
    names = _names(module)
    return [sorted({n for b in cell["connections"]["Q"] for n in names.get(b, [])} or {"?"})
            for cell in module["cells"].values() if cell["type"] in ENABLED_FF]


def enabled_reads(module):
    """MEMIDs of memories with a read port whose enable is not the constant 1."""
    return [c["parameters"].get("MEMID", "?").lstrip("\\") for c in module["cells"].values()
            if c["type"] == "$mem_v2" and any(b != "1" for b in c["connections"]["RD_EN"])]


def primitive_enables(module):
    """(cell type, pin) of every DP16KD CE/OCE and MULT18X18D CE pin not tied to 1."""
    pins = {"DP16KD": ("CEA", "CEB", "OCEA", "OCEB"), "MULT18X18D": ("CE0", "CE1", "CE2", "CE3")}
    return [(c["type"], pin) for c in module["cells"].values() if c["type"] in pins
            for pin in pins[c["type"]] if pin in c["connections"]
            and c["connections"][pin] != ["1"]]


def datapath_offenders(module):
    regs = [r for r in enabled_registers(module)
            if not any(n.startswith("edge.") or n in HOST_REGISTERS for n in r)]
    reads = [r for r in enabled_reads(module) if not r.startswith("edge.")]
    return regs, reads


def _unit(kind, method, target=None):
    cfg = Config() if method is None else Config(method=method)
    if kind == "fetch":
        cfg = load_scene_config("default", {"texture_size": 16})
    return build_unit(kind, cfg, target)[0]


@pytest.mark.parametrize("kind,method", UNIT_PARAMS)
def test_no_unit_register_or_read_has_an_enable(kind, method, build_dir):
    module = netlist(_unit(kind, method), "unit", build_dir)
    regs, reads = datapath_offenders(module)
    assert not regs and not reads, (regs, reads)
    assert any(n.startswith("edge.") for r in enabled_registers(module) for n in r)  # seen


@pytest.mark.parametrize("scene", SCENES)
def test_no_pipeline_register_or_read_has_an_enable(scene, build_dir):
    hw = load_scene_config(scene, {"texture_size": 16}).hardware
    module = netlist(BumpPipeline(hw), "top", build_dir / "generic")
    assert datapath_offenders(module) == ([], [])
    module = netlist(BumpPipeline(hw, target=ECP5()), "top", build_dir / "ecp5")
    assert primitive_enables(module) == []
    kinds = {c["type"] for c in module["cells"].values()}
    assert "DP16KD" in kinds                          # the check saw the block RAMs


@pytest.mark.parametrize("method", PLACED)
def test_no_placed_primitive_has_an_enable(method, build_dir):
    for kind in ("rotation", "illumination"):
        module = netlist(_unit(kind, method, ECP5()), kind, build_dir / kind)
        assert primitive_enables(module) == [], (kind, primitive_enables(module))


def test_the_check_finds_an_enable(build_dir):
    """A register with an enable outside the edge is reported by name (the check can fail)."""
    from amaranth.hdl import Module, Signal
    from amaranth.lib import wiring
    from amaranth.lib.wiring import In, Out

    class Held(wiring.Component):
        a: In(8)
        en: In(1)
        q: Out(8)

        def elaborate(self, platform):
            m = Module()
            held = Signal(8, name="held_value")
            with m.If(self.en):
                m.d.sync += held.eq(self.a)
            m.d.comb += self.q.eq(held)
            return m

    assert datapath_offenders(netlist(Held(), "held", build_dir)) == ([["held_value", "q"]], [])
