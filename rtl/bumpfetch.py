"""BumpMapFetch: texel coordinates in, the stored bump vector N' (or a palette index) out.

The bump vector map (Lee Sec. 2: per texel the tangent-space N' as polar angles) or the
index map of the palette method (Tarini Sec. 4) sits in one block RAM, mip levels one after
the other. With a colour texture (``texture = true``) a second block RAM of the same
geometry holds the RGB texels (8 bits per channel, r low) and is read at the same address
in the same cycle (``texel`` field). A flat bump map with a texture keeps only that memory.
:func:`texel_address` is the addressing arithmetic; it runs on Amaranth values here and on
int64 arrays in ``sim/golden/fixed/pipeline.py``, so both address alike.
"""

import numpy as np
from amaranth.hdl import Cat, Shape, Signal, Value, ValueCastable, signed, unsigned
from amaranth.lib import data
from amaranth.lib.wiring import In

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.fixed import Q, saturate
from bumprtl.rtl.layouts import polar_layout
from bumprtl.rtl.palette import index_bits
from bumprtl.rtl.pipe import RAM_LATENCY, PipeUnit
from bumprtl.rtl.scene import HardwareScene, check_scene
from bumprtl.rtl.targets import is_spread
from bumprtl.rtl.texture import rgb_layout

__all__ = ["BumpMapFetch", "texel_address", "level_coords", "level_bases", "memory_depth", "coord_bits",
           "level_bits", "texel_shape", "fetched_field", "fetched_fields", "has_map",
           "pack_texels", "pack_rgb", "spread_fetch", "fetch_latency", "TEXEL_BITS"]

TEXEL_BITS = 24               # one colour texel: r, g, b 8 bits each (Config.color_bits)


def coord_bits(scene):
    """Signed texel coordinates of level 0: [-2W, 2W) (W the map's width, at least its
    height), so two map widths either side of the map reach the wrap/clamp logic instead of
    wrapping silently in the port."""
    return scene.texture_bits + 2


def level_bits(scene):
    return (scene.mip_levels - 1).bit_length()


def _level_texels(scene):
    return [w * h for w, h in map(scene.level_size, range(scene.mip_levels))]


def level_bases(scene):
    """Word offset of each mip level: level l ((W >> l) x (H >> l) texels, row-major)
    follows level l-1."""
    sizes = _level_texels(scene)
    return [int(x) for x in np.concatenate([[0], np.cumsum(sizes)[:-1]])]


def memory_depth(scene):
    return sum(_level_texels(scene))


def fetched_field(scene):
    """The output field the fetch fills: ``b`` (N' angles) or ``index`` (palette)."""
    return "index" if scene.shading == "palette" else "b"


def has_map(scene):
    """The scene stores a per-texel map (N' angles or palette indices) in block RAM."""
    return scene.shading == "palette" or scene.bump_map == "varying"


def fetched_fields(scene):
    """Every field the fetch fills: the map's (:func:`fetched_field`) and ``texel``."""
    return ([fetched_field(scene)] if has_map(scene) else []) + (["texel"] if scene.texture else [])


def pack_rgb(rgb):
    """``(..., 3)`` 8-bit RGB -> one texture word per texel, r in the low bits."""
    v = np.asarray(rgb, np.int64)
    return v[..., 0] | (v[..., 1] << 8) | (v[..., 2] << 16)


def texel_shape(scene):
    """One stored texel: N' as polar angles (phi low, theta high) or a palette index."""
    cfg = scene.config
    return unsigned(index_bits(cfg)) if scene.shading == "palette" else polar_layout(cfg)


def pack_texels(scene, phi=None, theta=None, index=None):
    """Texel words (int64) from angle codes or palette indices, as the memory stores them."""
    if scene.shading == "palette":
        return np.asarray(index, np.int64)
    return np.asarray(phi, np.int64) | (np.asarray(theta, np.int64) << scene.angle_bits)


def _is_hdl(x):
    return isinstance(x, (Value, ValueCastable))


def _wrap(x, bits):
    return x[:bits] if _is_hdl(x) else np.asarray(x, np.int64) & ((1 << bits) - 1)


def level_coords(u, v, level, scene):
    """``(u_l, v_l)``, texel (u, v) (level-0 coordinates, signed) in constant mip ``level``:
    u_l = floor(u / 2**l), v_l = floor(v / 2**l), then wrap (u modulo W_l, v modulo H_l) or
    clamp (to [0, W_l - 1], [0, H_l - 1]), W_l x H_l the level's size."""
    coords = []
    for c, bits in ((u, scene.texture_bits - level), (v, scene.height_bits - level)):
        c, edge = c >> level, Q(bits, 0, signed=False)     # arithmetic: floor for negatives
        coords.append(_wrap(c, bits) if scene.addressing == "wrap" else saturate(c, edge))
    return tuple(coords)


def texel_address(u, v, level, scene):
    """Word address of texel (u, v) (level-0 coordinates, signed) at constant mip ``level``:
    (u_l, v_l) of :func:`level_coords`, then base_l + v_l W_l + u_l (W_l the level's width,
    a power of two: v_l's bits above u_l's)."""
    bits, v_bits = scene.texture_bits - level, scene.height_bits - level
    u_l, v_l = level_coords(u, v, level, scene)
    base = level_bases(scene)[level]
    if _is_hdl(u_l):
        return Cat(u_l[:bits], v_l[:v_bits]) + base if bits else Value.cast(base)
    return base + (v_l << bits) + u_l


def spread_fetch(scene):
    """A memory of the fetch (the map, the colour texture) is spread over more than
    targets.SPREAD_BLOCKS block RAMs: every read takes a second address register."""
    bits = [Shape.cast(texel_shape(scene)).width] if has_map(scene) else []
    bits += [TEXEL_BITS] if scene.texture else []
    return any(is_spread(memory_depth(scene), b) for b in bits)


def fetch_latency(scene):
    """Stages of :class:`BumpMapFetch` for ``scene``."""
    return 2 + RAM_LATENCY + spread_fetch(scene)


class BumpMapFetch(PipeUnit):
    """Bump vector map (or palette index map) in block RAM, one texel per clock.

    Parameters
    ----------
    scene : HardwareScene
        Reads ``texture_size`` T (power of two), ``addressing`` (wrap | clamp),
        ``mip_levels``, ``shading`` (palette: store indices) and the Config widths.
    out_layout : data.StructLayout, optional
        Output payload: the fetched field (``b`` or ``index``, see :func:`fetched_field`)
        plus fields forwarded unchanged from the input (default: ``tag``). The pipeline
        passes the next unit's input layout, so the two connect with ``wiring.connect``.
    init : sequence of int, optional
        Initial memory words (:func:`pack_texels`, levels one after the other from
        :func:`level_bases`); zeros when omitted.
    texture : sequence of int, optional
        Initial colour-texture words (:func:`pack_rgb`, same level layout); only with
        ``scene.texture``.
    write_port : bool
        True (default): the host write ports below; False: none, the memories hold their
        ``init`` and ``texture`` words for good (``bumprtl emit --load initial``).
    target : None or pipe.ECP5
        Elaboration target (None: the generic form every simulator runs).

    Members
    -------
    i : In(stream.Signature({u, v: signed(log2 T + 2), [level], <forwarded fields>}))
        Texel coordinates of level 0; ``level`` (only with ``mip_levels > 1``) values past
        the last level read the last level.
    o : Out(stream.Signature(out_layout))
        ``texel`` (rgb, with a texture) is filled like the map's field.
    w_en, w_addr, w_data : In
        Host write port (a scene's map loaded at run time). A read in the cycle of a write to
        the same word returns the old word. Absent with a flat bump map or without
        ``write_port``.
    tex_w_en, tex_w_addr, tex_w_data : In
        The colour texture's host write port (``texture = true`` and ``write_port``).

    Latency :func:`fetch_latency`: 2 + RAM_LATENCY (address register, block-RAM read, the
    block RAM's output register: rtl/pipe.RegisteredRAM, a DP16KD with REGMODE OUTREG on
    ECP5, so the RAM's clock-to-out stays out of the next unit's first cycle; then the word
    registered once more, so the route to the next unit has a cycle of its own), one more
    where a memory is spread (a second address register); 1 texel per clock when not
    stalled.
    """

    def __init__(self, scene: HardwareScene, out_layout=None, init=None, texture=None, target=None,
                 credit=True, fifo_depth=None, write_port=True):
        check_scene(self, scene)
        self.scene, self.write_port = scene, write_port
        self.fetched = fetched_fields(scene)
        if not self.fetched:
            self._MustUse__silence = True
            raise BumpError(f"scene {scene.name!r}: bump_map = 'flat' without a texture has "
                            f"nothing to fetch (BumpMapFetch needs bump_map = 'varying', "
                            f"shading = 'palette' or texture = true)")
        if out_layout is None:
            shapes = {fetched_field(scene): texel_shape(scene), "texel": rgb_layout(scene.config)}
            out_layout = data.StructLayout({**{f: shapes[f] for f in self.fetched},
                                            "tag": unsigned(scene.config.tag_bits)})
        self.out_layout = out_layout
        fields = {"u": signed(coord_bits(scene)), "v": signed(coord_bits(scene))}
        if scene.mip_levels > 1:
            fields["level"] = unsigned(level_bits(scene))
        fields.update({name: f.shape for name, f in out_layout if name not in self.fetched})
        self.depth = memory_depth(scene)
        self.word_bits = Shape.cast(texel_shape(scene)).width if has_map(scene) else 0
        self.latency = fetch_latency(scene)
        self.init = [int(w) for w in init] if init is not None else []
        self.texture = [int(w) for w in texture] if texture is not None else []
        for what, words in (("init", self.init), ("texture", self.texture)):
            if len(words) not in (0, self.depth):
                self._MustUse__silence = True
                raise ValueError(f"{what} has {len(words)} words, the map needs {self.depth}")
        if self.texture and not scene.texture:
            self._MustUse__silence = True
            raise ValueError("texture words given but the scene has texture = false")
        ports = {}
        if has_map(scene) and write_port:
            ports.update({"w_en": In(1), "w_addr": In(range(self.depth)),
                          "w_data": In(self.word_bits)})
        if scene.texture and write_port:
            ports.update({"tex_w_en": In(1), "tex_w_addr": In(range(self.depth)),
                          "tex_w_data": In(TEXEL_BITS)})
        super().__init__(scene.config, data.StructLayout(fields), out_layout, target, credit,
                         fifo_depth, ports)

    @property
    def memory_bits(self):
        return self.depth * (self.word_bits + (TEXEL_BITS if self.scene.texture else 0))

    def build(self, m, pipe):
        scene = self.scene
        mems = {}                                   # output field -> (RAM, host port prefix)
        if has_map(scene):
            mem = pipe.ram("map", self.depth, unsigned(self.word_bits), self.init,
                           self.write_port)
            mems[fetched_field(scene)] = mem, ""
        if scene.texture:
            mem = pipe.ram("texture", self.depth, unsigned(TEXEL_BITS), self.texture,
                           self.write_port)
            mems["texel"] = mem, "tex_"
        for mem, prefix in mems.values() if self.write_port else ():
            m.d.comb += [mem.w_en.eq(getattr(self, f"{prefix}w_en")),
                         mem.w_addr.eq(getattr(self, f"{prefix}w_addr")),
                         mem.w_data.eq(getattr(self, f"{prefix}w_data"))]

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
        addr_d1 = pipe.register(addr, "texel_addr_d1")                        # stage 1
        if spread_fetch(scene):       # a plain copy the placer puts beside the spread blocks
            addr_d1 = pipe.register(addr_d1, "texel_addr_near")
        for field, (mem, _) in mems.items():        # the same address, the same cycle
            m.d.comb += mem.r_addr.eq(addr_d1)      # then: read; the output register
            # stage 4: the word once more beside the block RAM, so the route to the next
            # unit has a cycle of its own wherever the placer puts the RAM
            m.d.comb += pipe.o.payload[field].eq(pipe.register(mem.r_data, f"{field}_word"))
        for name, _ in self.out_layout:
            if name not in self.fetched:
                m.d.comb += pipe.o.payload[name].eq(pipe.delay(px[name], self.latency, name))
