"""AXI4-Stream wrapper: a unit or a pipeline with AXI4-Stream port names and semantics.

``AxisWrapper(build, cfg, tdata_width=None)`` builds the unit with one more tag bit than
``cfg.tag_bits`` and puts AXI4-Stream ports around it:

``aclk``, ``aresetn``
    Clock and active-low synchronous reset (AMBA AXI4-Stream ACLK / ARESETn).
``s_axis_tdata``, ``s_axis_tvalid``, ``s_axis_tready``, ``s_axis_tuser``, ``s_axis_tlast``
    The unit's input stream: ``tdata`` is the payload without the tag, its fields packed
    from bit 0 in layout order (nested fields flattened, see :func:`axis_fields`) and zero
    padded to a whole number of bytes (``tdata_width``, a multiple of 8); ``tuser`` is
    the tag (``tag_bits`` wide, absent when 0).
``m_axis_tdata``, ``m_axis_tvalid``, ``m_axis_tready``, ``m_axis_tuser``, ``m_axis_tlast``
    The unit's output stream, packed the same way.
other ports
    The unit's host ports (palette table, bump map, polygon registers), unchanged.

``tlast``: the units process pixels one by one and do not know the line or frame length, so
the wrapper does not make ``tlast`` up: ``s_axis_tlast`` rides with its pixel through the
pipe, as the top bit of the internal tag, and comes out as ``m_axis_tlast`` on the same
pixel (end of line or end of frame: whatever the producer marked). Transfers are
``tvalid & tready``; ``m_axis_tvalid`` never waits for ``m_axis_tready`` and
``s_axis_tready`` is the unit's (or ``BumpPipeline``'s) ``i.ready``: a register, high
while one of its credits is free (rtl/pipe.CreditEdge), never a function of
``m_axis_tvalid`` or ``m_axis_tready`` in the same cycle. One transfer is one pixel: ``tkeep``/``tstrb`` are all ones and left
out. A config whose fields do not fit ``tdata_width`` raises :class:`AxisError` naming
the widths.
"""

from amaranth.hdl import Cat, ClockDomain, ClockSignal, Module, ResetSignal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.layouts import layout_fields

__all__ = ["AxisWrapper", "AxisError", "axis_fields", "tdata_bits", "MAX_TAG_BITS"]

MAX_TAG_BITS = 31            # Config allows 32; the wrapper needs one more for tlast


class AxisError(BumpError):
    """An AXI4-Stream request that cannot be met (the message names the widths)."""


def axis_fields(layout):
    """``{field: [tdata offset, width, signed]}`` of a payload layout without its tag:
    the leaf fields (dotted names) packed from bit 0 in layout order."""
    out, offset = {}, 0
    for name, (_off, width, sgn) in layout_fields(layout).items():
        if name == "tag":
            continue
        out[name] = [offset, width, sgn]
        offset += width
    return out


def tdata_bits(layout):
    """Payload bits without the tag, before byte padding."""
    return sum(w for _o, w, _s in axis_fields(layout).values())


def _byte_width(bits):
    return max(8, (bits + 7) // 8 * 8)


def _pack(payload, layout):
    """The tag-less payload of ``payload`` (a View) as a list of (tdata offset, value)."""
    flat = payload.as_value()
    src = layout_fields(layout)
    return [(off, flat[src[name][0]:src[name][0] + width])
            for name, (off, width, _s) in axis_fields(layout).items()]


class AxisWrapper(wiring.Component):
    """``build(cfg_with_one_more_tag_bit)`` -> unit, wrapped in AXI4-Stream ports.

    Parameters
    ----------
    build : callable
        Config (or HardwareScene) -> unit with ``i``/``o`` streams and a ``tag`` field.
    cfg : Config or rtl/scene.HardwareScene
        ``tag_bits`` is the ``tuser`` width; the unit is built with ``tag_bits + 1``.
    tdata_width : int, optional
        Width of both ``tdata`` buses, a multiple of 8 (default: the wider payload rounded
        up to whole bytes).
    """

    def __init__(self, build, cfg, tdata_width=None):
        tag_bits = cfg.tag_bits
        if tag_bits > MAX_TAG_BITS:
            self._MustUse__silence = True
            raise AxisError(f"tag_bits = {tag_bits}: the AXI4-Stream wrapper carries tlast as one "
                            f"more tag bit, allowed [0, {MAX_TAG_BITS}]")
        self.cfg = cfg
        self.unit = build(cfg.replace(tag_bits=tag_bits + 1))
        self.tag_bits = tag_bits
        in_layout = self.unit.i.payload.shape()
        out_layout = self.unit.o.payload.shape()
        self.in_layout, self.out_layout = in_layout, out_layout
        need = {"s_axis_tdata": tdata_bits(in_layout), "m_axis_tdata": tdata_bits(out_layout)}
        if tdata_width is None:
            tdata_width = _byte_width(max(need.values()))
        elif isinstance(tdata_width, bool) or not isinstance(tdata_width, int) \
                or tdata_width < 8 or tdata_width % 8:
            self.unit._MustUse__silence = self._MustUse__silence = True
            raise AxisError(f"tdata_width must be a positive multiple of 8 (whole bytes), "
                            f"got {tdata_width!r}")
        too_wide = {k: v for k, v in need.items() if v > tdata_width}
        if too_wide:
            self.unit._MustUse__silence = self._MustUse__silence = True
            raise AxisError(f"tdata_width = {tdata_width} is too narrow: " + ", ".join(
                f"{k} needs {v} bits ({', '.join(f'{n} {w}' for n, (_o, w, _s) in axis_fields(in_layout if k.startswith('s') else out_layout).items())})"
                for k, v in too_wide.items()) + f"; use --tdata-width {_byte_width(max(need.values()))} or more")
        self.tdata_width = tdata_width
        ports = {"aclk": In(1), "aresetn": In(1),
                 "s_axis_tdata": In(tdata_width), "s_axis_tvalid": In(1),
                 "s_axis_tready": Out(1), "s_axis_tlast": In(1),
                 "m_axis_tdata": Out(tdata_width), "m_axis_tvalid": Out(1),
                 "m_axis_tready": In(1), "m_axis_tlast": Out(1)}
        if tag_bits:
            ports.update({"s_axis_tuser": In(tag_bits), "m_axis_tuser": Out(tag_bits)})
        self._host = {}
        for name, member in self.unit.signature.members.items():
            if name not in ("i", "o"):
                ports[name] = member
                self._host[name] = member.flow
        super().__init__(ports)

    @property
    def latency(self):
        return self.unit.port_latency

    def sidecar(self):
        """The AXI4-Stream facts of the JSON sidecar."""
        return {"tdata_width": self.tdata_width, "tuser_width": self.tag_bits,
                "tuser": "the tag (side-band, rides with its pixel)" if self.tag_bits else None,
                "tlast": "passed through: rides with its pixel as internal tag bit "
                         f"{self.tag_bits}, m_axis_tlast marks the pixel s_axis_tlast marked "
                         "(the units do not know the line length)",
                "reset": "aresetn, active low, synchronous",
                "s_axis_tdata_fields": axis_fields(self.in_layout),
                "m_axis_tdata_fields": axis_fields(self.out_layout),
                "s_axis_tdata_bits": tdata_bits(self.in_layout),
                "m_axis_tdata_bits": tdata_bits(self.out_layout),
                "latency": self.latency}

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = ClockDomain("sync")
        m.d.comb += [ClockSignal("sync").eq(self.aclk), ResetSignal("sync").eq(~self.aresetn)]
        m.submodules.unit = unit = self.unit
        i, o, tb = unit.i, unit.o, self.tag_bits
        # Slave side: tdata fields into the payload, tuser and tlast into the tag.
        flat_in = i.payload.as_value()
        src = layout_fields(self.in_layout)
        for name, (off, width, _s) in axis_fields(self.in_layout).items():
            base = src[name][0]
            m.d.comb += flat_in[base:base + width].eq(self.s_axis_tdata[off:off + width])
        tag_in = Cat(self.s_axis_tuser, self.s_axis_tlast) if tb else self.s_axis_tlast
        m.d.comb += [i.payload.tag.eq(tag_in), i.valid.eq(self.s_axis_tvalid),
                     self.s_axis_tready.eq(i.ready)]
        # Master side.
        for off, value in _pack(o.payload, self.out_layout):
            m.d.comb += self.m_axis_tdata[off:off + len(value)].eq(value)
        m.d.comb += [self.m_axis_tlast.eq(o.payload.tag[tb]), self.m_axis_tvalid.eq(o.valid),
                     o.ready.eq(self.m_axis_tready)]
        if tb:
            m.d.comb += self.m_axis_tuser.eq(o.payload.tag[:tb])
        for name, flow in self._host.items():
            inner, outer = getattr(unit, name), getattr(self, name)
            if flow == In:
                m.d.comb += inner.eq(outer)
            else:
                m.d.comb += outer.eq(inner)
        return m
