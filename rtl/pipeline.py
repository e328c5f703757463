"""BumpPipeline: the per-pixel system a scene needs, generated from a HardwareScene
(docs/architecture.md, Scenes decide what is built).

texel coordinates + world N, L, H in; shaded pixels out. Only what the scene needs is built:

* varying bump map: BumpMapFetch -> VectorRotation -> Illumination;
* flat bump map: no map and no per-pixel N' rotation: n'' is rotated once per polygon
  (``sim/golden/fixed/pipeline.polygon_fixed``) and written to the polygon registers, per
  pixel only the light terms (:class:`VectorTerms`) and the dots remain;
* palette shading: BumpMapFetch (indices) -> PaletteLUT, no rotation at all;
* m lights share the one rotated normal n'' (exact method): light 0 rides in VectorRotation,
  lights 1..m-1 in one :class:`VectorTerms`, one Illumination per light, :class:`LightSum`;
* no H path and no specular table without specular (the units read ``cfg.specular``);
* colour texture (``texture = true``): the RGB texel is read from a second block RAM at the
  same (u, v[, level]) as the bump map, carried beside the rotation and illumination layers
  (:class:`TexelDelay`) and blended with the shade by :class:`TextureBlend` (rtl/texture.py;
  the shape of Tarini et al.'s eq. 2), which also sums the lights; palette shading blends it
  in PaletteLUT's eq. 2 as the base colour. Without a texture none of this is built.

Free-running units and one credit edge (rtl/pipe.py): every unit is built with
``credit=False``, so none has a clock enable and none reads a ``ready``: the units form one
shift register, valid bit beside payload, and a bubble is a pixel with valid low. The
pipeline has one :class:`~bumprtl.rtl.pipe.CreditEdge`: ``i.ready`` is "a credit is free"
(a register), the first unit sees ``i.valid & i.ready``, and the last unit writes a FIFO of
``fifo_depth`` entries (at least ``min_fifo_depth(latency)``) whose head is ``o``; a pixel
taken at ``o`` gives its credit back. At the ports: ``i.ready`` never depends on ``i.valid``
or ``o.ready`` in the same cycle; ``o.valid``/``o.payload`` come from the FIFO's output
register and never depend on ``o.ready``.
"""

from amaranth.hdl import Assert, Cat, Const, Module, Mux, Signal, unsigned
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.bumpfetch import BumpMapFetch, has_map
from bumprtl.rtl.cache import AxiMapFetch
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.exact import (
    SineBank,
    rotated_layout,
    rotation_latency,
    vector_terms,
)
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.layouts import angle_shape, light_fields, light_layout, pixel_layout, shade_layout
from bumprtl.rtl.palette import PaletteLUT
from bumprtl.rtl.pipe import (
    EDGE_LATENCY,
    PRODUCT_LATENCY,
    PipeUnit,
    add_credit_edge,
    check_fifo_depth,
    pipe_observer,
)
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.rtl.scene import HardwareScene, check_scene
from bumprtl.rtl.tables import (
    COLOR_FRAC_BITS,
    KD_FRAC_BITS,
    KS_FRAC_BITS,
    SPEC_FRAC_BITS,
    phong_coefficients,
)
from bumprtl.rtl.texture import TexelDelay, TextureBlend, rgb_layout, sum_product

__all__ = ["BumpPipeline", "VectorTerms", "LightSum"]


def _vector_layout(cfg):
    return rotated_layout(cfg)["l"].shape


class VectorTerms(PipeUnit):
    """The per-vector half of the exact rotation (docs/architecture.md, The exact angular
    method) for each vector A of ``count`` lights:
    D = ph_A - ph_N, X = th_A + D, Y = th_A - D, 2p = s(X) + s(Y), 2y = c(Y) - c(X),
    z = c(th_A). Built by ``exact.vector_terms``, the function ``exact.ExactRotation`` uses, with
    the same latency, so it runs in lock step beside it. Input {n_phi, lights:
    ArrayLayout(light_layout, count), tag}; output {lights: ArrayLayout({l, [h]: {p2, y2, z}},
    count), tag}. ``first``: the pipeline's number of the first of these lights (its
    registers are named ``l_*``, ``l1_*``, ... after the pipeline's lights)."""

    def __init__(self, cfg, count, first=0, target=None, credit=True, fifo_depth=None):
        self.count, self.first = count, first
        self.latency = rotation_latency(cfg)
        terms = data.StructLayout({v: _vector_layout(cfg) for v, _ in light_layout(cfg)})
        fields_in = {"n_phi": angle_shape(cfg), "lights": data.ArrayLayout(light_layout(cfg), count),
                     "tag": unsigned(cfg.tag_bits)}
        fields_out = {"lights": data.ArrayLayout(terms, count), "tag": unsigned(cfg.tag_bits)}
        super().__init__(cfg, data.StructLayout(fields_in), data.StructLayout(fields_out), target,
                         credit, fifo_depth)

    def build(self, m, pipe):
        rom = SineBank(m, pipe, self.cfg)
        px, out = self.i.payload, pipe.o.payload
        for k in range(self.count):
            j = self.first + k                     # the pipeline's light number
            for v, _ in light_layout(self.cfg):
                label = v + str(j) if j else v
                terms = vector_terms(pipe, rom, px.lights[k][v], px.n_phi, label, self.latency)
                m.d.comb += [out.lights[k][v][name].eq(value) for name, value in terms.items()]
        m.d.comb += out.tag.eq(pipe.delay(px.tag, self.latency, "tag"))


class LightSum(PipeUnit):
    """m lights' unrounded diffuse and specular terms -> the pixel (eq. 2 summed over the
    lights, rounded once). Input {d: ArrayLayout(unsigned(B + 1), m), s: ArrayLayout(
    unsigned(8 + F), m) (light j's ``diffuse_fine``, ``specular_fine`` at index j), tag};
    with D = sum d_j, S = sum s_j:
    diffuse = min(255, round(255 D)), specular = min(255, round(S / 2**F)),
    color = min(255, round((KA + floor(KD D / 2**B) + floor(KS S / 2**16)) / 2**G))
    (rtl/shade.py's Phong sum). Output ``shade_layout(cfg, fine=False)``.
    Latency 5 (products, each product sum alone, the Phong terms' sum, its rounding and
    clamp: the two 2-operand stages of rtl/shade.shade_stages; the 8-bit sums: 255 D, the
    rounding, the clamp); bit-exact with
    ``sim/golden/fixed/pipeline.combine_lights_fixed``."""

    # Registers: the products' operands and outputs (PRODUCT_LATENCY), the sums of the split
    # products (kd, ks), the terms' sum, the colour.
    latency = PRODUCT_LATENCY + 3

    def __init__(self, scene: HardwareScene, target=None, credit=True, fifo_depth=None):
        check_scene(self, scene)
        cfg, self.lights = scene.config, scene.lights
        fields = {"d": data.ArrayLayout(unsigned(cfg.frac_bits + 1), self.lights),
                  "s": data.ArrayLayout(unsigned(8 + SPEC_FRAC_BITS), self.lights),
                  "tag": unsigned(cfg.tag_bits)}
        super().__init__(cfg, data.StructLayout(fields), shade_layout(cfg, fine=False), target,
                         credit, fifo_depth)

    def build(self, m, pipe):
        px, b, g = self.i.payload, self.cfg.frac_bits, COLOR_FRAC_BITS
        d = pipe.register(sum(px.d[j] for j in range(self.lights)), "diffuse_sum")
        s = pipe.register(sum(px.s[j] for j in range(self.lights)), "specular_sum")
        ka, kd, ks = phong_coefficients(self.cfg)
        # KD d, KS s from the stage-1 inputs: DSP products whose operand registers are d's and
        # s's (rtl/texture.sum_product: the widths, a split by lights where a sum is too wide)
        kd_term = sum_product([px.d[j] for j in range(self.lights)], b + 1, kd, pipe.multiply,
                              "kd_sum")
        ks_term = sum_product([px.s[j] for j in range(self.lights)], 8 + SPEC_FRAC_BITS, ks,
                              pipe.multiply, "ks_sum")
        sat = lambda x: Mux(x > 255, 255, x)[:8]
        # the 8-bit sums: 255 D, the rounding, then the clamp (one carry chain a cycle)
        d255 = pipe.register((d << 8) - d, "diffuse255")                             # stage 2
        s8 = pipe.register(round_shift(s, SPEC_FRAC_BITS), "specular8_round")
        d8 = pipe.register(round_shift(d255, b), "diffuse8_round")                  # stage 3
        s8 = pipe.register(s8, "specular8_round_d3")
        d8, s8 = pipe.register(sat(d8), "diffuse8"), pipe.register(sat(s8), "specular8")  # 4
        # KD d, KS s: stage PRODUCT_LATENCY = 2
        # round_shift(KA + kd + ks, G) as in shade_stages: the terms' sum, then KA and the
        # rounding half (one constant), the shift and the clamp.
        # (a DSP output feeds one adder a cycle: kd and ks, each a sum of up to MAX_SPLIT
        # products, are registered before their sum)
        kd_term = pipe.register(kd_term >> (KD_FRAC_BITS + b - g), "kd_phong")      # stage 3
        ks_term = pipe.register(ks_term >> (KS_FRAC_BITS + SPEC_FRAC_BITS - g), "ks_phong")
        terms = pipe.register(kd_term + ks_term, "phong_terms")                    # stage 4
        total = (terms + (ka + (1 << (g - 1)))) >> g
        o = pipe.o.payload
        m.d.comb += [o.color.eq(pipe.register(sat(total), "color")),                # 5
                     o.diffuse.eq(pipe.delay(d8, self.latency - 4, "diffuse")),
                     o.specular.eq(pipe.delay(s8, self.latency - 4, "specular")),
                     o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))]


class _Entry:
    """A valid bit and a payload: the source of a unit's input in the chain."""

    def __init__(self, valid, payload):
        self.valid, self.payload = valid, payload


def _same_valid(m, src, dsts):
    """Feed one stream's valid to the free-running units of one layer."""
    m.d.comb += [dst.valid.eq(src.valid) for dst in dsts]


def _feed(m, src, dst):
    """``src`` into ``dst`` of the next layer: valid and payload."""
    m.d.comb += [dst.valid.eq(src.valid), dst.payload.eq(src.payload)]


class BumpPipeline(wiring.Component):
    """The per-pixel pipeline of one scene.

    Parameters
    ----------
    scene : HardwareScene
        What to build (rtl/scene.py; ``SceneConfig.hardware`` of a scene file or built-in
        scene).
    init : sequence of int, optional
        Bump map / index map words of the fetch unit (``BumpMapFetch`` ``init``).
    texture : sequence of int, optional
        Colour-texture words (``bumpfetch.pack_rgb``, same level layout as the map).
    write_port : bool
        True (default): the map's and texture's host write ports; False: none, the memories
        hold ``init`` and ``texture`` for good (``bumprtl emit --load initial``).
    target : None or pipe.ECP5
        Elaboration target of every unit (None: the generic form every simulator runs).

    Members
    -------
    i : In(stream.Signature(...))
        varying map: {u, v, [level], n, l, [h], [extra_lights], tag}; flat map:
        {[u, v, [level] with a texture], l, [h], [extra_lights], tag}; palette: {u, v,
        [level], tag}. Light 0's vectors are ``l``, ``h``; with m > 1 lights
        ``extra_lights[j - 1]`` = {l, [h]} holds light j's (``layouts.light_fields``).
        Angles are binary angles.
    o : Out(stream.Signature(...))
        ``shade_layout`` (diffuse, specular, color, diffuse_fine, specular_fine, tag; with
        m > 1 lights LightSum's, without the fine terms); with a texture TextureBlend's
        {diffuse, specular, color: rgb, tag}; or PaletteLUT's {color: rgba, oor, tag} with
        palette shading.
    map_w_en, map_w_addr, map_w_data : In
        Host write port of the bump map (varying map and palette; only with ``write_port``).
    tex_w_en, tex_w_addr, tex_w_data : In
        Host write port of the colour texture (``texture = true``; only with ``write_port``).
    poly_en, poly : In
        Flat map: the polygon registers {n_phi, x4, y2, z4} (n'' rotated once per polygon).
    lut_w_en, lut_w_addr, lut_w_data, lut_swap, lut_bank, lut_w_ready :
        Palette: PaletteLUT's host port. The pipeline samples the front bank (``lut_bank``)
        in the cycle it accepts a pixel and the pixel carries it through the fetch: every
        pixel reads the bank that was in front when the *pipeline* accepted it, whatever the
        host swaps while it is in flight, so a frame (the pixels between two swaps) reads
        one bank and a swap takes effect with the first pixel accepted after it. A write
        (``lut_w_en``, to the back bank) is done in a cycle with ``lut_w_ready`` high, a
        valid/ready handshake: the host holds ``lut_w_en``/``addr``/``data`` until it sees
        ``lut_w_ready``. It is low while a pixel accepted before the last swap still waits
        in the fetch stages to read the back bank (at most the fetch latency after the swap
        without backpressure; with ``map_memory = "axi"`` until those pixels have left the
        cache); before the first pixel and between frames it is high.

    ``latency`` is the sum of the units' latencies (the free-running chain);
    ``port_latency`` adds the edge's EDGE_LATENCY (a pixel taken at ``i`` is offered at
    ``o`` that many cycles later with the FIFO empty); 1 pixel per clock while the sink
    takes one per clock. ``fifo_depth`` (None: the least, ``min_fifo_depth(latency)``; or a
    function of ``latency`` giving it) is the FIFO's depth and the number of credits.
    ``built`` lists the units and why each was built; after elaboration ``memories`` lists
    every unit's memories (``unit.name`` -> depth, width, bits).

    The edge (submodule ``edge``, :class:`~bumprtl.rtl.pipe.CreditEdge`: its ``credits``
    and ``level``) is read by sim/formal's credit invariant.

    With ``map_memory = "axi"`` the fetch is :class:`~bumprtl.rtl.cache.AxiMapFetch` (the
    map in the user's memory behind a texel cache, port ``axi``, ``cache`` its
    :class:`~bumprtl.rtl.cache.CacheGeometry` parameters; with palette shading the index
    map, PaletteLUT behind the edge) in front of the credit edge: when
    the cache has to wait (its queue full, a miss that cannot issue) it stalls ``i`` alone
    and the free-running chain behind the edge keeps its contract;
    ``i.ready`` is then the cache's (it depends on the lookup in the same cycle), and
    ``port_latency`` adds the cache's hit latency.
"""

    def __init__(self, scene: HardwareScene, init=None, texture=None, target=None,
                 write_port=True, fifo_depth=None, cache=None):
        self.scene = check_scene(self, scene)
        self._front = scene.map_memory == "axi"     # the fetch before the credit edge
        write_port = write_port and not self._front  # the map is in the user's memory
        self.write_port = write_port
        self.cache = cache
        self.cfg = cfg = scene.config
        self.target = target
        self.units, self.built = {}, []
        self._texture = texture
        ports = {}
        if scene.shading == "palette":
            self._plan_palette(init)
        else:
            self._plan_shading(init)
        if "fetch" in self.units:
            in_layout = self.units["fetch"].i.payload.shape()
            if scene.shading == "palette":          # the bank rides inside, from lut_bank
                in_layout = data.StructLayout({f: in_layout[f].shape for f, _ in in_layout
                                               if f != "bank"})
        else:                                       # flat map: the light vectors and the tag
            in_layout = data.StructLayout({**light_fields(cfg), "tag": unsigned(cfg.tag_bits)})
        ports["i"] = In(stream.Signature(in_layout))
        out_layout = self.units[self._last].o.payload.shape()
        ports["o"] = Out(stream.Signature(out_layout))
        if callable(fifo_depth):                    # a function of the latency
            fifo_depth = fifo_depth(self.latency)
        try:
            self.fifo_depth = check_fifo_depth(self.latency, fifo_depth)
        except BumpError:
            self._MustUse__silence = True
            raise
        if self._front:
            ports["axi"] = Out(self.units["fetch"].axi.signature)
        if "fetch" in self.units and has_map(scene) and write_port:
            f = self.units["fetch"]
            ports.update({"map_w_en": In(1), "map_w_addr": In(f.w_addr.shape()),
                          "map_w_data": In(f.w_data.shape())})
        if scene.texture and write_port:
            f = self.units["fetch"]
            ports.update({"tex_w_en": In(1), "tex_w_addr": In(f.tex_w_addr.shape()),
                          "tex_w_data": In(f.tex_w_data.shape())})
        if scene.rotation == "per-polygon":
            ports.update({"poly_en": In(1), "poly": In(self._poly_layout())})
        if scene.shading == "palette":
            lut = self.units["palette"]
            ports.update({"lut_w_en": In(1), "lut_w_addr": In(lut.w_addr.shape()),
                          "lut_w_data": In(lut.w_data.shape()), "lut_swap": In(1),
                          "lut_bank": Out(1), "lut_w_ready": Out(1)})
        super().__init__(ports)

    # --- planning: which units, and why -----------------------------------------------------
    def _add(self, name, unit, why):
        self.units[name] = unit
        self.built.append({"unit": name, "class": type(unit).__name__, "latency": unit.latency,
                           "why": why})

    def _fetch(self, out_layout, init, what):
        s = self.scene
        texels = s.map_label
        if s.texture:                          # the RGB texel from the parallel texture RAM
            fields = {f: out_layout[f].shape for f, _ in out_layout if f not in ("tag", "base")}
            out_layout = data.StructLayout({**fields, "texel": rgb_layout(self.cfg),
                                            "tag": out_layout["tag"].shape})
        if self._front:
            key = "shading = 'palette'" if s.shading == "palette" else "bump_map = 'varying'"
            self._add("fetch", AxiMapFetch(s, out_layout, self.cache, self.target),
                      f"{key}, map_memory = 'axi': {what} per texel from the "
                      f"user's memory through a texel cache ({texels} texels, "
                      f"{s.mip_levels} level(s), {s.addressing} addressing)")
            return
        maps = ([f"bump_map = 'varying': {what}"] if has_map(s) else []) + \
            (["texture = true: the RGB colour texel"] if s.texture else [])
        self._add("fetch", BumpMapFetch(s, out_layout, init, self._texture, self.target,
                                        credit=False,
                                        write_port=self.write_port),
                  f"{' and '.join(maps)} per texel in block RAM ({texels} texels, "
                  f"{s.mip_levels} level(s), {s.addressing} addressing)")

    def _plan_palette(self, init):
        lut = PaletteLUT(self.cfg, self.target, bank_in=True, credit=False)
        self._fetch(lut.i.payload.shape(), init, "a palette index")
        if self.scene.texture:
            self.built[-1]["why"] += "; the texel is PaletteLUT's eq. 2 base colour (alpha 255)"
        self._add("palette", lut, "shading = 'palette': one colour-table lookup per pixel, "
                                  "no per-pixel rotation")
        self._layers = ([] if self._front else [["fetch"]]) + [["palette"]]
        self._first, self._last = self._layers[0][0], "palette"
        self._rot_layer = self._ill_layer = None

    def _plan_shading(self, init):
        s, cfg = self.scene, self.cfg
        spec = "with the H path and specular table" if s.specular else \
            "specular = false: no H path, no specular table"
        rot_layer = []
        if s.rotation == "per-pixel":
            fields = {name: f.shape for name, f in pixel_layout(cfg)}
            tag = fields.pop("tag")
            fields.update(light_fields(cfg))   # l, h stay in place; extra_lights after b
            self._fetch(data.StructLayout({**fields, "tag": tag}), init, "N' (polar angles)")
            self._add("rotation", VectorRotation(cfg, self.target, credit=False),
                      f"rotation = 'per-pixel': N' rotated into N's frame every pixel ({spec})")
            rot_layer.append("rotation")
            first = 1                          # light 0 rides in the rotation
        else:
            first = 0
            if s.texture:                      # no bump map, but the colour texture is fetched
                self._fetch(data.StructLayout({**light_fields(cfg), "tag": unsigned(cfg.tag_bits)}),
                            init, "")
        if s.lights > first:
            why = ("bump_map = 'flat': n'' written once per polygon, per pixel only the light "
                   "terms" if s.rotation == "per-polygon" else
                   f"lights = {s.lights}: lights 1..{s.lights - 1} share light 0's rotated normal")
            self._add("terms", VectorTerms(cfg, s.lights - first, first, self.target,
                                          credit=False), why)
            rot_layer.append("terms")
        ill = []
        for j in range(s.lights):
            name = f"illumination{j}" if s.lights > 1 else "illumination"
            self._add(name, Illumination(cfg, self.target, credit=False),
                      f"light {j}: N'.L' (and N'.H') and the shade of eq. 2 ({spec})")
            ill.append(self.built[-1]["unit"])
        if s.texture:                          # the texel rides beside both layers
            for name, layer in (("texel_r", rot_layer), ("texel_i", ill)):
                latency = self.units[layer[0]].latency
                self._add(name, TexelDelay(cfg, latency, self.target, credit=False),
                          f"texture = true: the texel waits {latency} stages beside {layer[0]}")
                layer.append(name)
        self._layers = ([["fetch"]] if "fetch" in self.units and not self._front else []) + \
            [rot_layer, ill]
        self._rot_layer, self._ill_layer = rot_layer, ill
        if s.texture:
            self._add("blend", TextureBlend(cfg, s.lights, self.target, credit=False),
                      "texture = true: out_c = tex_c min(1, ka + kd d) + ks s (Lee eq. 2 with a "
                      "textured albedo, Tarini eq. 2's shape)" +
                      (f", summed over the {s.lights} lights" if s.lights > 1 else ""))
            self._layers.append(["blend"])
        elif s.lights > 1:
            self._add("lightsum", LightSum(s, self.target, credit=False),
                      f"lights = {s.lights}: eq. 2 summed over the lights")
            self._layers.append(["lightsum"])
        self._first, self._last = self._layers[0][0], self._layers[-1][0]

    def _poly_layout(self):
        n = rotated_layout(self.cfg)["n"].shape
        return data.StructLayout({"n_phi": angle_shape(self.cfg), "n": n})

    @property
    def skipped(self):
        """The units of the full pipeline this scene does not build, and why."""
        s, out = self.scene, []
        if not s.specular and s.shading == "per-pixel":
            out.append({"unit": "H path + specular table", "why": "specular = false"})
        if s.rotation == "per-polygon":
            out.append({"unit": "bump map RAM + per-pixel N' rotation" if s.texture else
                        "fetch + per-pixel N' rotation",
                        "why": "bump_map = 'flat': n'' rotated once per polygon"})
        if s.shading == "palette":
            out.append({"unit": "rotation + illumination", "why": "shading = 'palette'"})
        if s.lights == 1 and s.shading == "per-pixel":
            out.append({"unit": "extra light terms + light sum", "why": "lights = 1"})
        elif s.texture and s.shading == "per-pixel":
            out.append({"unit": "light sum", "why": "texture = true: the blend sums the lights"})
        if not s.texture:
            out.append({"unit": "colour-texture blend", "why": "texture = false"})
        return out

    @property
    def latency(self):
        return sum(self.units[layer[0]].latency for layer in self._layers)

    @property
    def port_latency(self):
        return self.latency + EDGE_LATENCY + (self.units["fetch"].latency if self._front else 0)

    @property
    def front_capacity(self):
        """Pixels the texel cache in front of the credit edge holds at most (its
        ``capacity``; 0 without one): taken at ``i``, not yet counted by the credits."""
        return self.units["fetch"].capacity if self._front else 0

    # --- elaboration ------------------------------------------------------------------------
    def elaborate(self, platform):
        m = Module()
        if self._front:                       # the cache, then the edge and the chain
            front = self.units["fetch"]
            if self.scene.shading != "palette":   # the palette's fetch also takes the bank
                wiring.connect(m, wiring.flipped(self.i), front.i)
            wiring.connect(m, wiring.flipped(self.axi), front.axi)
        _, core = add_credit_edge(m, front.o if self._front else self.i, self.o, self.latency,
                                  self.fifo_depth)
        _feed(m, self.units[self._last].o, core)
        for name, unit in self.units.items():
            m.submodules[name] = unit
        s, u = self.scene, self.units
        for prefix in ("map_", "tex_"):
            if hasattr(self, f"{prefix}w_en"):
                f, port = u["fetch"], prefix.replace("map_", "")
                m.d.comb += [getattr(f, f"{port}w_{k}").eq(getattr(self, f"{prefix}w_{k}"))
                             for k in ("en", "addr", "data")]
        if s.shading == "palette":
            self._elaborate_palette(m, platform)
            return m
        if s.lights == 1 and s.rotation == "per-pixel" and not s.texture:  # fetch -> rotation -> illumination
            if self._front:
                _feed(m, self._taken(), u["rotation"].i)
            else:
                _feed(m, self._taken(), u["fetch"].i)
                _feed(m, u["fetch"].o, u["rotation"].i)
            _feed(m, u["rotation"].o, u["illumination"].i)
            return m
        self._elaborate_layers(m)
        return m

    def _taken(self):
        """The pixel entering the first unit: ``i``'s payload, valid when it is taken (the
        cache's output with ``map_memory = "axi"``)."""
        if self._front:
            front = self.units["fetch"].o
            return _Entry(front.valid & front.ready, front.payload)
        return _Entry(self.i.valid & self.i.ready, self.i.payload)

    def _elaborate_layers(self, m):
        s, u, cfg = self.scene, self.units, self.cfg
        vectors = [v for v, _ in light_layout(cfg)]
        if "fetch" in u and not self._front:
            _feed(m, self._taken(), u["fetch"].i)
            src = u["fetch"].o
        else:
            src = self._taken()
        rot_layer, ill_layer = self._rot_layer, self._ill_layer
        poly = self._poly_reg(m) if s.rotation == "per-polygon" else None
        _same_valid(m, src, [u[n].i for n in rot_layer])
        if "rotation" in u:
            m.d.comb += [u["rotation"].i.payload[f].eq(src.payload[f])
                         for f, _ in pixel_layout(cfg)]
        # light j's l, h: light 0's at the top of the payload, the others in extra_lights
        given = [src.payload] + [src.payload.extra_lights[k] for k in range(s.lights - 1)]
        terms = u.get("terms")
        if terms is not None:
            t = terms.i.payload
            m.d.comb += t.n_phi.eq(src.payload.n.phi if poly is None else poly.n_phi)
            m.d.comb += [t.lights[k][v].eq(given[terms.first + k][v])
                         for k in range(terms.count) for v in vectors]
            m.d.comb += t.tag.eq(src.payload.tag)
        if s.texture:
            m.d.comb += u["texel_r"].i.payload.texel.eq(src.payload.texel)
        lead = u[rot_layer[0]].o
        _same_valid(m, lead, [u[n].i for n in ill_layer])
        n_src = u["rotation"].o.payload.n if poly is None else poly.n
        # light j's rotated l, h: light 0's from the rotation (varying map), the rest from terms
        rotated = ([u["rotation"].o.payload] if "rotation" in u else []) + \
            ([terms.o.payload.lights[k] for k in range(terms.count)] if terms is not None else [])
        for j, name in enumerate(ill_layer[:s.lights]):
            ill = u[name].i.payload
            m.d.comb += [ill.n.eq(n_src), ill.tag.eq(lead.payload.tag)]
            m.d.comb += [ill[v].eq(rotated[j][v]) for v in vectors]
        if s.texture:
            m.d.comb += u["texel_i"].i.payload.texel.eq(u["texel_r"].o.payload.texel)
        lead = u[ill_layer[0]].o
        if s.lights == 1 and not s.texture:
            return
        total = u["blend"] if s.texture else u["lightsum"]
        _same_valid(m, lead, [total.i])
        for j, n in enumerate(ill_layer[:s.lights]):
            m.d.comb += [total.i.payload.d[j].eq(u[n].o.payload.diffuse_fine),
                         total.i.payload.s[j].eq(u[n].o.payload.specular_fine)]
        if s.texture:
            m.d.comb += total.i.payload.texel.eq(u["texel_i"].o.payload.texel)
        m.d.comb += total.i.payload.tag.eq(lead.payload.tag)

    def _elaborate_palette(self, m, platform):
        """fetch -> PaletteLUT; the front bank sampled at the input rides with the pixel
        (with ``map_memory = "axi"`` through the cache, the LUT behind the credit edge)."""
        lut, f = self.units["palette"], self.units["fetch"]
        if self._front:                        # i -> cache; its output, when taken -> LUT
            m.d.comb += [f.i.valid.eq(self.i.valid), self.i.ready.eq(f.i.ready)]
        else:
            m.d.comb += f.i.valid.eq(self._taken().valid)
        m.d.comb += f.i.payload.bank.eq(lut.bank)
        m.d.comb += [f.i.payload[name].eq(self.i.payload[name]) for name, _ in self.i.payload.shape()]
        if self.scene.texture:                 # Tarini eq. 2: the texel is the base colour
            m.d.comb += [lut.i.valid.eq(f.o.valid), lut.i.payload.index.eq(f.o.payload.index),
                         lut.i.payload.base.eq(Cat(f.o.payload.texel.as_value(), Const(255, 8))),
                         lut.i.payload.bank.eq(f.o.payload.bank),
                         lut.i.payload.tag.eq(f.o.payload.tag)]
        else:
            _feed(m, self._taken() if self._front else f.o, lut.i)
        # Pixels between the input and the LUT per bank they read: a write to the back bank
        # waits (lut_w_ready low) while one of them still has to read it. The fetch holds
        # its latency's pixels, the cache up to its capacity (its queue and registers).
        take_in, take_lut = self.i.valid & self.i.ready, lut.i.valid & lut.i.ready
        held = f.capacity if self._front else f.latency
        waiting = [Signal(range(held + 1), name=f"lut_bank{b}_pending") for b in (0, 1)]
        observer = pipe_observer(platform)         # sim/formal's bank lemmas read them
        if observer is not None and hasattr(observer, "counter"):
            observer.counter(self, "lut_pending", waiting)
        # busy: count != 0 as a register of its own (loaded with the next count's test), so
        # the write enable of the table's block RAMs comes from a register through one gate
        busy = [Signal(name=f"lut_bank{b}_busy") for b in (0, 1)]
        for b, count in enumerate(waiting):
            after = Signal.like(count, name=f"lut_bank{b}_pending_next")
            m.d.comb += after.eq(count + (take_in & (lut.bank == b))
                                 - (take_lut & (lut.i.payload.bank == b)))
            m.d.sync += [count.eq(after), busy[b].eq(after != 0)]
            if platform == "formal":
                m.d.comb += Assert(busy[b] == (count != 0))
        m.d.comb += [self.lut_w_ready.eq(~Mux(lut.bank, busy[0], busy[1])),
                     lut.w_en.eq(self.lut_w_en & self.lut_w_ready),
                     lut.w_addr.eq(self.lut_w_addr), lut.w_data.eq(self.lut_w_data),
                     lut.swap.eq(self.lut_swap), self.lut_bank.eq(lut.bank)]

    def _poly_reg(self, m):
        """The polygon registers, written by the host when ``poly_en`` (once per polygon)."""
        reg = Signal(self._poly_layout(), name="polygon")
        with m.If(self.poly_en):
            m.d.sync += reg.eq(self.poly)
        return reg
