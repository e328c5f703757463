"""``bumprtl emit UNIT --interface axis``: a unit or pipeline in AXI4-Stream ports
(rtl/axis.py), written as ``<unit>_axis.v`` with its ``<unit>_axis.json`` sidecar.

The sidecar is the unit's own (config with the user's ``tag_bits``, latency, ROM sizes,
error bound) plus ``interface: axis`` and ``axis``: tdata width, the tdata field packing of
both buses, the tuser/tlast conventions and the reset.
"""

import json

from bumprtl.gen.flow.emit import emit
from bumprtl.gen.flow.units import SCENE_UNITS, UNITS, canonical_command
from bumprtl.rtl.axis import AxisWrapper
from bumprtl.rtl.config import BumpError

__all__ = ["build_axis", "emit_axis", "axis_name"]


def axis_name(name):
    return f"{name}_axis"


def build_axis(name, cfg, tdata_width=None):
    """``(wrapper, sidecar, command)`` for unit ``name`` in AXI4-Stream ports."""
    if name not in UNITS:
        raise BumpError(f"unit must be one of {', '.join(UNITS)}, got {name!r}")
    unit = UNITS[name]
    wrapper = AxisWrapper(lambda c: unit.build(c, target=None), cfg, tdata_width)
    inner = unit.sidecar(cfg.replace(tag_bits=cfg.tag_bits + 1), wrapper.unit)
    sidecar = {**inner, "config": cfg.config.to_dict() if name in SCENE_UNITS else cfg.to_dict(),
               "interface": "axis", "axis": wrapper.sidecar()}
    if "scene" in inner:
        sidecar["scene"] = cfg.to_dict()
    command = canonical_command(unit, cfg) + " --interface axis"
    if tdata_width is not None:
        command += f" --tdata-width {tdata_width}"
    return wrapper, sidecar, command


def emit_axis(name, cfg, out_dir, tdata_width=None):
    """Write ``<out_dir>/<name>_axis.v`` and ``.json`` (one flattened module); returns the
    two paths."""
    wrapper, sidecar, command = build_axis(name, cfg, tdata_width)
    v_path, j_path = emit(wrapper, axis_name(name), command, out_dir, sidecar, flatten=True)
    meta = json.loads(j_path.read_text())
    for port in ("clk", "rst"):                 # aclk/aresetn instead (port_table adds these)
        meta["ports"].pop(port, None)
    j_path.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
    return v_path, j_path
