"""``bumprtl emit UNIT --interface axis``: a unit or pipeline in AXI4-Stream ports
(rtl/axis.py), written as ``<unit>_axis.v`` with its ``<unit>_axis.json`` sidecar.

The sidecar is the unit's own (config with the user's ``tag_bits``, latency, ROM sizes,
error bound) plus ``interface: axis`` and ``axis``: tdata width, the tdata field packing of
both buses, the tuser/tlast conventions and the reset.

A scene unit (``pipeline``, ``fetch``) is built with its memory images
(gen/flow/memories.py ``memory_images``): the ``load = "initial"`` ones as the Verilog's
initial contents (and then without the map's and texture's host write ports), each written
beside it as ``<unit>_axis_<memory>.hex`` and described in the sidecar's ``memory_images``,
as ``bumprtl emit`` does without ``--interface axis``.
"""

from pathlib import Path

from bumprtl.gen.flow.emit import emit, port_table
from bumprtl.gen.flow.memories import has_write_port, hex_text, image_records, scene_command
from bumprtl.gen.flow.units import SCENE_UNITS, UNITS, canonical_command, name_flag
from bumprtl.rtl.axis import AxisWrapper
from bumprtl.rtl.bumpfetch import BumpMapFetch
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import from_facts

__all__ = ["build_axis", "emit_axis", "axis_name"]


def axis_name(name):
    return f"{name}_axis"


def _builder(name, images):
    """Config (a scene unit: HardwareScene) -> the unit, with the initial contents of
    ``images`` for a scene unit."""
    if name not in SCENE_UNITS:
        return lambda c: UNITS[name].build(c, target=None)
    if not images:
        return BumpPipeline if name == "pipeline" else BumpMapFetch
    init = lambda n: images[n]["words"] if n in images and images[n]["load"] == "initial" else None
    cls = BumpPipeline if name == "pipeline" else BumpMapFetch
    return lambda hardware: cls(hardware, init=init("map"), texture=init("texture"),
                                write_port=has_write_port(images))


def build_axis(name, cfg, tdata_width=None, images=None, module=None):
    """``(wrapper, sidecar, command)`` for unit ``name`` in AXI4-Stream ports (``sidecar``
    a :class:`~bumprtl.rtl.sidecar.Sidecar`); ``images``:
    a scene unit's memory images (``memory_images``), None for empty memories; ``module``:
    the name the wrapper is emitted under is ``<module>_axis`` (default ``name``)."""
    if name not in UNITS:
        raise BumpError(f"unit must be one of {', '.join(UNITS)}, got {name!r}")
    unit = UNITS[name]
    wrapper = AxisWrapper(_builder(name, images), cfg.hardware if name in SCENE_UNITS else cfg,
                          tdata_width)
    inner = unit.sidecar(cfg.replace(tag_bits=cfg.tag_bits + 1), wrapper.unit)
    facts = {**inner, "config": cfg.config.to_dict() if name in SCENE_UNITS else cfg.to_dict(),
               "interface": "axis", "axis": wrapper.sidecar()}
    if "scene" in inner:
        facts["scene"] = cfg.to_dict()
    if images:
        facts["memory_images"] = {
            n: {**img, "file": f"{axis_name(module or name)}_{n}.hex"}
            for n, img in image_records(images, has_write_port(images)).items()}
    command = (canonical_command(unit, cfg) if name not in SCENE_UNITS or not images
               else scene_command(name, cfg, _load(images))) + " --interface axis"
    if tdata_width is not None:
        command += f" --tdata-width {tdata_width}"
    command += name_flag(name, module)
    ports = {n: p for n, p in port_table(wrapper).items()     # aclk/aresetn, not clk/rst
             if n not in ("clk", "rst")}
    return wrapper, from_facts(axis_name(name), command, ports, facts), command


def _load(images):
    return images["map"]["load"] if "map" in images else "initial"


def emit_axis(name, cfg, out_dir, tdata_width=None, images=None, module=None):
    """Write ``<out_dir>/<name>_axis.v`` and ``.json`` (one flattened module) and, for a
    scene unit with ``images``, one ``$readmemh`` file per image; returns ``(v, json,
    [hex...])``."""
    wrapper, sidecar, command = build_axis(name, cfg, tdata_width, images, module)
    v_path, j_path = emit(wrapper, axis_name(name), command, out_dir, sidecar, flatten=True,
                          module=axis_name(module) if module else None)
    hexes = []
    for n, img in (images or {}).items():
        path = Path(out_dir) / sidecar.memory_images[n]["file"]
        path.write_text(hex_text(img["words"], img["width"]))
        hexes.append(path)
    return v_path, j_path, hexes
