"""The emittable units: name -> how to build the Component and its sidecar facts.

``bumprtl emit NAME`` and the tests go through :func:`build_unit`, so the CLI, the tests
and the reports elaborate exactly the same hardware from the same Config.
"""

from collections.abc import Callable
from dataclasses import dataclass

from bumprtl.gen.flow.emit import emit, memory_records, port_table
from bumprtl.rtl.bumpfetch import BumpMapFetch, fetched_fields, level_bases
from bumprtl.rtl.config import ANGLE_BITS_RANGE, FRAC_BITS_MAX, BumpError, Config
from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.palette import PaletteLUT, index_bits
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.rtl.sidecar import from_facts
from bumprtl.rtl.sincos import SinCos, sine_rom_table
from bumprtl.sim.golden.methods import METHODS, get

__all__ = ["UNITS", "SCENE_UNITS", "Unit", "build_unit", "emit_unit", "unit_sidecar", "unit_memories",
           "canonical_command", "default_module", "name_flag", "bound_fields", "error_bounds", "faithful_widths", "faithful_note"]


def default_module(unit):
    """The top module (and file) name ``bumprtl emit UNIT`` writes without ``--name``."""
    return f"bumprtl_{unit}"


def name_flag(unit, module):
    """``--name MODULE`` for the command line that reproduces a unit emitted as ``module``
    (empty for :func:`default_module` and for None, the unit's bare name the tests use)."""
    return "" if module in (None, default_module(unit)) else f" --name {module}"


@dataclass(frozen=True)
class Unit:
    name: str
    help: str
    build: Callable        # (Config or SceneConfig, target) -> Component
    sidecar: Callable      # (Config, Component) -> dict of derived facts (rtl/sidecar.py from_facts)
    flags: tuple = ("angle_bits", "frac_bits", "tag_bits")   # Config fields on the CLI


def _flow(dut):
    """The flow facts every unit's sidecar states: its port latency (credit edge included),
    its FIFO depth (= credits) and one item a clock."""
    return {"latency": dut.port_latency, "fifo_depth": dut.fifo_depth, "throughput": 1}


def _sincos_sidecar(cfg, dut):
    width = sine_rom_table(cfg)[1]
    return {**_flow(dut),
            "roms": {"quarter_sine": {"depth": cfg.sincos_depth, "width": width,
                                      "bits": cfg.sincos_depth * width}},
            "error_bound_ulp": 0.5}


def _method_sidecar(cfg, dut):
    """A rotation or illumination unit: its method's error bound and note (rtl/methods.py)."""
    method = get(cfg.method)
    return {**_flow(dut), "method": cfg.method, "roms": unit_memories(dut),
            **bound_fields(error_bounds(cfg)), **faithful_widths(cfg),
            "error_note": method.error_note}


def bound_fields(bounds):
    """The sidecar's bound fields: ``error_bounds_lsb`` (per channel) and ``error_bound_lsb``,
    the largest of them: the bound of the unit as a whole."""
    return {"error_bound_lsb": max(bounds.values()), "error_bounds_lsb": bounds}


def error_bounds(cfg, lights=1, texture=False):
    """The method's proven bound per output channel (8-bit LSB vs float64 on unquantized
    inputs; the registry's ``predicted_error_bound_lsb``, proofs in its docstring): diffuse,
    specular (0 without specular) and color (the texture blend's with ``texture``), summed
    over ``lights``. A Config whose widths cannot reach 1 LSB still emits: its sidecar states
    the larger bound."""
    bound = get(cfg.method).predicted_error_bound_lsb
    out = {c: bound(cfg, c, lights) for c in ("diffuse", "specular")}
    if not cfg.specular:
        out["specular"] = 0
    out["color"] = bound(cfg, "blend" if texture else "color", lights)
    return out


def faithful_widths(cfg):
    """``{"faithful_widths": {"angle_bits", "frac_bits"} or None}``: the narrowest widths at
    which the method's bound proves every output channel within 1 LSB of float64 at
    ``cfg``'s other fields (the registry's ``faithful_widths``; None: no widths in the
    Config's range do; without specular the exponent plays no part); ``{}`` for a method
    that does not search them."""
    rule = get(cfg.method).faithful_widths
    if rule is None:
        return {}
    widths = rule(cfg if cfg.specular else cfg.replace(spec_exponent=1))
    return {"faithful_widths": None if widths is None else
            {"angle_bits": widths[0], "frac_bits": widths[1]}}


def faithful_note(cfg, lights=1, texture=False):
    """One line for the command line when a proven bound of ``cfg`` exceeds 1 LSB: the
    channels over it and the widths that prove every channel within it (or that none in
    the Config's range do). None when every bound is 1 or the method searches no widths."""
    found = faithful_widths(cfg)
    over = {c: b for c, b in error_bounds(cfg, lights, texture).items() if b > 1}
    if not found or not over:
        return None
    bounds = ", ".join(f"{c} {b} LSB" for c, b in over.items())
    want = found["faithful_widths"]
    fix = (f"angle_bits {want['angle_bits']}, frac_bits {want['frac_bits']} prove every "
           f"channel within 1 LSB" if want else
           f"no widths up to the Config's angle_bits {ANGLE_BITS_RANGE[1]}, frac_bits "
           f"{FRAC_BITS_MAX} prove 1 LSB at spec_exponent {cfg.spec_exponent}")
    return (f"note: proven error bounds at angle_bits {cfg.angle_bits}, frac_bits "
            f"{cfg.frac_bits}: {bounds} (sidecar error_bounds.lsb_per_channel; measured errors: "
            f"bumprtl bench accuracy); {fix}")


def unit_memories(dut):
    """Every memory of a unit: name -> depth, width, bits (ROM sizes in bits), as its pipe
    built them in the one elaboration emission converts (``emit.memory_records``, see
    rtl/pipe.MemoryRecords); ``unit.name`` for each unit of a pipeline."""
    records = memory_records(dut)
    if isinstance(dut, BumpPipeline):
        found = {f"{unit}.{name}": size for unit, u in dut.units.items()
                 for name, size in records.of(u).items()}
    else:
        found = records.of(dut)
    return dict(sorted(found.items()))


def _palette_sidecar(cfg, dut):
    return {**_flow(dut), "index_bits": index_bits(cfg),
            "blend": "eq2" if cfg.palette_blend else None, "roms": unit_memories(dut),
            "memory_bits": dut.memory_bits, "double_buffered": True,
            "out_of_range_index": "reads as all zeros (rgba = 0) and sets oor = 1; "
                                  "host writes to addresses >= palette_size are ignored"}


def _pipeline_sidecar(scene, dut):
    """Which units were built and why, which were skipped, latency, memories."""
    out = {"config": scene.config.to_dict(), "scene": scene.to_dict(), **_flow(dut),
           "built": dut.built, "skipped": dut.skipped, "roms": unit_memories(dut)}
    if scene.shading == "per-pixel":
        out.update(bound_fields(error_bounds(scene.config, scene.lights, scene.texture)))
        out.update(faithful_widths(scene.config))
    return out


def _fetch_sidecar(scene, dut):
    return {"config": scene.config.to_dict(), "scene": scene.to_dict(), **_flow(dut),
            "outputs": fetched_fields(scene), "level_bases": level_bases(scene),
            "memory_bits": dut.memory_bits, "addressing": scene.addressing}


_METHOD_FLAG = f"--method {'|'.join(METHODS)}"

UNITS = {
    "sincos": Unit("sincos", "quarter-wave sin/cos ROM unit (toolchain slice)",
                   SinCos, _sincos_sidecar),
    "rotation": Unit("rotation", ("VectorRotation or a baseline's setup (Lee Sec. 3.1, Table 1; "
                                  f"{_METHOD_FLAG})"),
                     VectorRotation, _method_sidecar,
                     ("method", "angle_bits", "frac_bits", "tag_bits", "specular")),
    "illumination": Unit("illumination", f"Illumination (Lee Sec. 3.2, Table 1; {_METHOD_FLAG})",
                         Illumination, _method_sidecar,
                         ("method", "angle_bits", "frac_bits", "tag_bits", "specular",
                          "spec_exponent", "spec_index_bits", "ka", "kd", "ks")),
    "palette": Unit("palette", "PaletteLUT (Tarini Sec. 5/7.2): index -> RGBA, double-buffered table",
                    PaletteLUT, _palette_sidecar,
                    ("palette_size", "color_bits", "palette_blend", "tag_bits")),
    # These two take a SceneConfig (``bumprtl emit pipeline --scene FILE|NAME``).
    "pipeline": Unit("pipeline", "BumpPipeline: the units a scene needs (--scene FILE|NAME)",
                     lambda scene, target=None: BumpPipeline(scene.hardware, target=target),
                     _pipeline_sidecar, ("scene",)),
    "fetch": Unit("fetch", "BumpMapFetch: (u, v[, level]) -> N' or palette index (--scene FILE|NAME)",
                  lambda scene, target=None: BumpMapFetch(scene.hardware, target=target), _fetch_sidecar,
                  ("scene",)),
}
SCENE_UNITS = ("pipeline", "fetch")


def canonical_command(unit, cfg, module=None):
    """The ``bumprtl emit`` line that reproduces a unit: its name and its Config flags
    (and ``--name`` when ``module`` is neither None nor the default)."""
    parts = ["bumprtl", "emit", unit.name]
    for field in unit.flags:
        value = getattr(cfg, field)
        flag = "--" + field.replace("_", "-")
        if isinstance(value, bool):
            parts.append(flag if value else "--no-" + field.replace("_", "-"))
        else:
            parts += [flag, str(value)]
    return " ".join(parts) + name_flag(unit.name, module)


def build_unit(name, cfg: Config, target=None):
    """Elaborate unit ``name``: returns ``(component, sidecar, command)``, ``sidecar`` the
    :class:`~bumprtl.rtl.sidecar.Sidecar` ``bumprtl emit`` writes (the unit's bare name as
    its module). ``target``: None (the generic form ``bumprtl emit`` writes) or
    ``rtl.pipe.ECP5()`` (gen/flow/fpga.py)."""
    if name not in UNITS:
        raise BumpError(f"unit must be one of {', '.join(UNITS)}, got {name!r}")
    unit = UNITS[name]
    dut = unit.build(cfg, target=target)
    facts = {"config": cfg.to_dict(), **unit.sidecar(cfg, dut)}
    command = canonical_command(unit, cfg)
    return dut, from_facts(name, command, port_table(dut), facts), command


def unit_sidecar(name, cfg, module=None):
    """The :class:`~bumprtl.rtl.sidecar.Sidecar` ``emit_unit`` writes, without the Verilog
    (the unit is elaborated for its memory records, not converted)."""
    sidecar = build_unit(name, cfg)[1]
    return sidecar.replace(command=canonical_command(UNITS[name], cfg, module),
                           module=module or name)


def emit_unit(name, cfg, out_dir, module=None):
    """Emit ``<out_dir>/<module>.v`` and ``.json`` (``module`` default: ``name``); returns
    the two paths."""
    dut, sidecar, _ = build_unit(name, cfg)
    command = canonical_command(UNITS[name], cfg, module)
    return emit(dut, name, command, out_dir, sidecar, flatten=name in SCENE_UNITS, module=module)
