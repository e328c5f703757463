"""The emittable units: name -> how to build the Component and its sidecar facts.

``bumprtl emit NAME`` and the tests go through :func:`build_unit`, so the CLI, the tests
and the reports elaborate exactly the same hardware from the same Config.
"""

from dataclasses import dataclass
from typing import Callable

from bumprtl.rtl.config import BumpError, Config

__all__ = ["UNITS", "SCENE_UNITS", "Unit", "build_unit", "canonical_command"]


@dataclass(frozen=True)
class Unit:
    name: str
    help: str
    build: Callable        # Config -> Component
    sidecar: Callable      # (Config, Component) -> dict of derived facts
    flags: tuple = ("angle_bits", "frac_bits", "tag_bits")   # Config fields on the CLI


def _sincos():
    from bumprtl.rtl.sincos import SinCos
    return SinCos


def _sincos_sidecar(cfg, dut):
    return {"latency": dut.latency, "throughput": 1,
            "roms": {"quarter_sine": {"depth": cfg.sincos_depth, "width": cfg.frac_bits + 1,
                                      "bits": cfg.sincos_depth * (cfg.frac_bits + 1)}},
            "error_bound_ulp": 0.5}


def _rotation_sidecar(cfg, dut):
    from bumprtl.sim.golden.fixed.exact import predicted_error_bound_lsb
    facts = {"latency": dut.latency, "throughput": 1, "method": cfg.method, "roms": _roms(dut)}
    if cfg.method == "exact":
        facts["error_bound_lsb"] = predicted_error_bound_lsb(cfg)
        facts["error_note"] = "diffuse vs float64 on unquantized inputs (proof: predicted_error_bound_lsb)"
    elif cfg.method == "kim":
        from bumprtl.sim.golden.fixed.kim import predicted_error_bound_lsb as kim_bound
        facts["error_bound_lsb"] = kim_bound(cfg)
        facts["error_note"] = "diffuse vs float64 on unquantized inputs (proof: fixed_kim.predicted_error_bound_lsb)"
    elif cfg.method in ("peercy", "ernst"):
        from bumprtl.sim.golden.fixed.peercy import predicted_error_bound_lsb as cartesian_bound
        facts["error_bound_lsb"] = cartesian_bound(cfg)
        facts["error_note"] = ("diffuse vs float64 on unquantized inputs, Cartesian input codes from "
                               "fixed_peercy.encode (proof: fixed_peercy.predicted_error_bound_lsb)")
    else:
        # The rigid-circle and proportion approximations (DESIGN §3 item 7) are geometric:
        # no width bounds the error below the full 8-bit range.
        facts["error_bound_lsb"] = 255
        facts["error_note"] = ("lee's geometric approximations: measured max ~215 LSB of diffuse "
                               "vs float64 at every width (bumprtl bench float64, bench lee-widths)")
    return facts


def _roms(dut):
    """Every memory of an elaborated unit: name -> depth, width, bits (ROM sizes in bits)."""
    from amaranth.hdl import Fragment, MemoryData, Shape
    roms = {}

    def walk(frag, path):
        data = getattr(frag, "_data", None)      # a MemoryInstance carries its MemoryData
        if isinstance(data, MemoryData):
            width = Shape.cast(data.shape).width
            roms[path] = {"depth": data.depth, "width": width, "bits": data.depth * width}
        for sub, name, _ in getattr(frag, "subfragments", ()):
            walk(sub, f"{path}.{name}" if path else str(name))

    walk(Fragment.get(dut, None), "")
    return roms


def _palette_sidecar(cfg, dut):
    from bumprtl.rtl.palette import index_bits
    return {"latency": dut.latency, "throughput": 1, "index_bits": index_bits(cfg),
            "blend": "eq2" if cfg.palette_blend else None, "roms": _roms(dut),
            "memory_bits": dut.memory_bits, "double_buffered": True,
            "out_of_range_index": "reads as all zeros (rgba = 0) and sets oor = 1; "
                                  "host writes to addresses >= palette_size are ignored"}


def _pipeline_sidecar(scene, dut):
    """Which units were built and why, which were skipped, latency, memories."""
    return {"config": scene.config.to_dict(), "scene": scene.to_dict(), "latency": dut.latency,
            "throughput": 1, "built": dut.built, "skipped": dut.skipped, "roms": _roms(dut)}


def _fetch_sidecar(scene, dut):
    from bumprtl.rtl.bumpfetch import fetched_fields, level_bases
    return {"config": scene.config.to_dict(), "scene": scene.to_dict(), "latency": dut.latency,
            "throughput": 1, "outputs": fetched_fields(scene), "level_bases": level_bases(scene),
            "memory_bits": dut.memory_bits, "addressing": scene.addressing}


UNITS = {
    "sincos": Unit("sincos", "quarter-wave sin/cos ROM unit (toolchain slice)",
                   lambda cfg: _sincos()(cfg), _sincos_sidecar),
    "rotation": Unit("rotation", ("VectorRotation or a baseline's setup (Lee Sec. 3.1, Table 1; "
                                  "--method exact|lee|peercy|ernst|kim)"),
                     lambda cfg: _rtl("rotation", "VectorRotation")(cfg), _rotation_sidecar,
                     ("method", "angle_bits", "frac_bits", "tag_bits", "specular")),
    "illumination": Unit("illumination", ("Illumination (Lee Sec. 3.2, Table 1; "
                                          "--method exact|lee|peercy|ernst|kim)"),
                         lambda cfg: _rtl("illumination", "Illumination")(cfg), _rotation_sidecar,
                         ("method", "angle_bits", "frac_bits", "tag_bits", "specular",
                          "spec_exponent", "spec_index_bits", "ka", "kd", "ks")),
    "palette": Unit("palette", "PaletteLUT (Tarini Sec. 5/7.2): index -> RGBA, double-buffered table",
                    lambda cfg: _rtl("palette", "PaletteLUT")(cfg), _palette_sidecar,
                    ("palette_size", "color_bits", "palette_blend", "tag_bits")),
    # These two take a SceneConfig (``bumprtl emit pipeline --scene FILE|NAME``).
    "pipeline": Unit("pipeline", "BumpPipeline: the units a scene needs (--scene FILE|NAME)",
                     lambda scene: _rtl("pipeline", "BumpPipeline")(scene), _pipeline_sidecar,
                     ("scene",)),
    "fetch": Unit("fetch", "BumpMapFetch: (u, v[, level]) -> N' or palette index (--scene FILE|NAME)",
                  lambda scene: _rtl("bumpfetch", "BumpMapFetch")(scene), _fetch_sidecar,
                  ("scene",)),
}
SCENE_UNITS = ("pipeline", "fetch")


def _rtl(module, name):
    import importlib
    return getattr(importlib.import_module(f"bumprtl.rtl.{module}"), name)


def canonical_command(unit, cfg):
    """The ``bumprtl emit`` line that reproduces a unit: its name and its Config flags."""
    parts = ["bumprtl", "emit", unit.name]
    for field in unit.flags:
        value = getattr(cfg, field)
        flag = "--" + field.replace("_", "-")
        if isinstance(value, bool):
            parts.append(flag if value else "--no-" + field.replace("_", "-"))
        else:
            parts += [flag, str(value)]
    return " ".join(parts)


def build_unit(name, cfg: Config):
    """Elaborate unit ``name``: returns ``(component, sidecar_dict, command)``."""
    if name not in UNITS:
        raise BumpError(f"unit must be one of {', '.join(UNITS)}, got {name!r}")
    unit = UNITS[name]
    dut = unit.build(cfg)
    sidecar = {"config": cfg.to_dict(), **unit.sidecar(cfg, dut)}
    return dut, sidecar, canonical_command(unit, cfg)


def emit_unit(name, cfg, out_dir):
    """Emit ``<out_dir>/<name>.v`` and ``.json``; returns the two paths."""
    from bumprtl.gen.flow.emit import emit
    dut, sidecar, command = build_unit(name, cfg)
    return emit(dut, name, command, out_dir, sidecar, flatten=name in SCENE_UNITS)
