"""BumpMapFetch: texel coordinates in, the stored bump vector N' (or a palette index) out.

The bump vector map (Lee Sec. 2: per texel the tangent-space N' as polar angles) or the
index map of the palette method (Tarini Sec. 4) sits in one block RAM, mip levels one after
the other. :func:`texel_address` is the addressing arithmetic; it runs on Amaranth values
here and on int64 arrays in ``sim/golden/fixed_pipeline.py``, so both address alike.
"""

import numpy as np
from amaranth.hdl import Cat, Module, Shape, Signal, Value, ValueCastable, signed, unsigned
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from .fixed import Q, saturate
from .layouts import polar_layout
from .palette import index_bits
from .pipe import StallPipe
from .scene import SceneConfig

__all__ = ["BumpMapFetch", "texel_address", "level_bases", "memory_depth", "coord_bits",
           "level_bits", "texel_shape", "fetched_field", "pack_texels"]


def coord_bits(scene: SceneConfig):
    """Signed texel coordinates of level 0: [-2T, 2T), so two map widths either side of the
    map reach the wrap/clamp logic instead of wrapping silently in the port."""
    return scene.texture_bits + 2


def level_bits(scene: SceneConfig):
    return (scene.mip_levels - 1).bit_length()


def level_bases(scene: SceneConfig):
    """Word offset of each mip level: level l (T >> l squared texels) follows level l-1."""
    sizes = [(scene.texture_size >> n) ** 2 for n in range(scene.mip_levels)]
    return [int(x) for x in np.concatenate([[0], np.cumsum(sizes)[:-1]])]


def memory_depth(scene: SceneConfig):
    return sum((scene.texture_size >> n) ** 2 for n in range(scene.mip_levels))


def fetched_field(scene: SceneConfig):
    """The output field the fetch fills: ``b`` (N' angles) or ``index`` (palette)."""
    return "index" if scene.shading == "palette" else "b"


def texel_shape(scene: SceneConfig):
    """One stored texel: N' as polar angles (phi low, theta high) or a palette index."""
    cfg = scene.config
    return unsigned(index_bits(cfg)) if scene.shading == "palette" else polar_layout(cfg)


def pack_texels(scene: SceneConfig, phi=None, theta=None, index=None):
    """Texel words (int64) from angle codes or palette indices, as the memory stores them."""
    if scene.shading == "palette":
        return np.asarray(index, np.int64)
    return np.asarray(phi, np.int64) | (np.asarray(theta, np.int64) << scene.angle_bits)


def _is_hdl(x):
    return isinstance(x, (Value, ValueCastable))


def _wrap(x, bits):
    return x[:bits] if _is_hdl(x) else np.asarray(x, np.int64) & ((1 << bits) - 1)


def texel_address(u, v, level, scene: SceneConfig):
    """Word address of texel (u, v) (level-0 coordinates, signed) at constant mip ``level``:
    u_l = floor(u / 2**l), then wrap (modulo T_l) or clamp (to [0, T_l - 1]), then
    base_l + v_l T_l + u_l."""
    bits = scene.texture_bits - level
    edge = Q(bits, 0, signed=False)
    coords = []
    for c in (u, v):
        c = c >> level                                     # arithmetic: floor for negatives
        coords.append(_wrap(c, bits) if scene.addressing == "wrap" else saturate(c, edge))
    u_l, v_l = coords
    base = level_bases(scene)[level]
    if _is_hdl(u_l):
        return Cat(u_l[:bits], v_l[:bits]) + base if bits else Value.cast(base)
    return base + (v_l << bits) + u_l


class BumpMapFetch(wiring.Component):
    """Bump vector map (or palette index map) in block RAM, one texel per clock.

    Parameters
    ----------
    scene : SceneConfig
        Reads ``texture_size`` T (power of two), ``addressing`` (wrap | clamp),
        ``mip_levels``, ``shading`` (palette: store indices) and the Config widths.
    out_layout : data.StructLayout, optional
        Output payload: the fetched field (``b`` or ``index``, see :func:`fetched_field`)
        plus fields forwarded unchanged from the input (default: ``tag``). The pipeline
        passes the next unit's input layout, so the two connect with ``wiring.connect``.
    init : sequence of int, optional
        Initial memory words (:func:`pack_texels`, levels one after the other from
        :func:`level_bases`); zeros when omitted.

    Members
    -------
    i : In(stream.Signature({u, v: signed(log2 T + 2), [level], <forwarded fields>}))
        Texel coordinates of level 0; ``level`` (only with ``mip_levels > 1``) values past
        the last level read the last level.
    o : Out(stream.Signature(out_layout))
    w_en, w_addr, w_data : In
        Host write port (a scene's map loaded at run time). A read in the cycle of a write to
        the same word returns the old word.

    Latency 2 (address register, block-RAM read); 1 texel per clock when not stalled.
    """

    latency = 2

    def __init__(self, scene: SceneConfig, out_layout=None, init=None):
        self.scene, self.cfg = scene, scene.config
        field = fetched_field(scene)
        if out_layout is None:
            out_layout = data.StructLayout({field: texel_shape(scene),
                                            "tag": unsigned(self.cfg.tag_bits)})
        self.out_layout = out_layout
        fields = {"u": signed(coord_bits(scene)), "v": signed(coord_bits(scene))}
        if scene.mip_levels > 1:
            fields["level"] = unsigned(level_bits(scene))
        fields.update({name: f.shape for name, f in out_layout if name != field})
        self.depth = memory_depth(scene)
        self.word_bits = Shape.cast(texel_shape(scene)).width
        self.init = [int(w) for w in init] if init is not None else []
        if len(self.init) not in (0, self.depth):
            self._MustUse__silence = True
            raise ValueError(f"init has {len(self.init)} words, the map needs {self.depth}")
        super().__init__({
            "i": In(stream.Signature(data.StructLayout(fields))),
            "o": Out(stream.Signature(out_layout)),
            "w_en": In(1),
            "w_addr": In(range(self.depth)),
            "w_data": In(self.word_bits),
        })

    @property
    def memory_bits(self):
        return self.depth * self.word_bits

    def elaborate(self, platform):
        scene, field = self.scene, fetched_field(self.scene)
        m = Module()
        pipe = StallPipe(m, self.i, self.o, self.latency)
        m.submodules.map = mem = Memory(shape=unsigned(self.word_bits), depth=self.depth,
                                        init=self.init)
        wp = mem.write_port()
        m.d.comb += [wp.en.eq(self.w_en), wp.addr.eq(self.w_addr), wp.data.eq(self.w_data)]

        px = self.i.payload
        addr = Signal(range(self.depth), name="texel_addr")
        if scene.mip_levels == 1:
            m.d.comb += addr.eq(texel_address(px.u, px.v, 0, scene))
        else:
            with m.Switch(px.level):
                for level in range(scene.mip_levels - 1):
                    with m.Case(level):
                        m.d.comb += addr.eq(texel_address(px.u, px.v, level, scene))
                with m.Default():                         # last level, and past it
                    m.d.comb += addr.eq(texel_address(px.u, px.v, scene.mip_levels - 1, scene))
        rp = mem.read_port(domain="sync")
        m.d.comb += [rp.en.eq(pipe.adv),
                     rp.addr.eq(pipe.register(addr, "texel_addr_d1"))]     # stage 1
        m.d.comb += self.o.payload[field].eq(rp.data)                       # stage 2
        for name, _ in self.out_layout:
            if name != field:
                m.d.comb += self.o.payload[name].eq(pipe.delay(px[name], self.latency, name))
        return m
