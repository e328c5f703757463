"""The exact angular method in hardware (docs/architecture.md): rotate N' once, not L and H.

N'.(M A) = (R_y(th_N) n') . A_z with A_z = R_z(-ph_N) A. Everything is a sum of sines and
cosines of angle sums read from quarter-wave ROMs (product-to-sum), then 3 multiplies per
vector: 6 multipliers, 24 sin/cos reads and no division or inverse trig per pixel.
Bit-exact with ``sim/golden/fixed/exact.py``.
"""

from amaranth.hdl import signed
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.layouts import pixel_layout
from bumprtl.rtl.pipe import PRODUCT_LATENCY, WIDE_PRODUCT_LATENCY, PipeUnit, fits_dsp
from bumprtl.rtl.shade import IlluminationDatapath
from bumprtl.rtl.sincos import (
    near_sine,
    registered_quarter_wave_rom,
    registered_sine_latency,
    sine_line,
    sine_read,
)

__all__ = ["ExactRotation", "ExactIllumination", "SineBank", "rotated_layout", "rotation_latency",
           "vector_terms", "vectors"]


def vectors(cfg: Config):
    """The vectors dotted with N': L, and H when the scene has specular."""
    return ("l", "h") if cfg.specular else ("l",)


def rotated_layout(cfg: Config):
    """Rotation output: n'' (scaled x4, x2, x4) and p, y, cos th per vector (scaled x2, x2,
    x1), all with frac_bits fractional bits; widths hold the exact sums (no rounding)."""
    b = cfg.frac_bits
    fields = {"n": data.StructLayout({"x4": signed(b + 5), "y2": signed(b + 3), "z4": signed(b + 5)})}
    for v in vectors(cfg):
        fields[v] = data.StructLayout({"p2": signed(b + 3), "y2": signed(b + 3), "z": signed(b + 2)})
    fields["tag"] = pixel_layout(cfg)["tag"].shape
    return data.StructLayout(fields)


class SineBank:
    """Dual-port quarter-wave ROMs, two reads each (one block RAM per pair on an FPGA);
    a value read appears ``latency`` pipe stages after its angle (angle register,
    folded index, address register, [its near copy for a wide ROM,] read, block-RAM output register,
    data register, its copy, sign: sincos.registered_sine_latency)."""

    def __init__(self, m, pipe, cfg):
        self.m, self.pipe, self.cfg, self.roms, self.pending = m, pipe, cfg, [], []
        self.near, self.latency = near_sine(cfg), registered_sine_latency(cfg)
        self.line = sine_line(cfg)

    def _port(self):
        if not self.pending:
            rom = registered_quarter_wave_rom(self.pipe, self.cfg, f"sine_rom{len(self.roms)}")
            self.roms.append(rom)
            self.pending = list(rom.ports)
        return self.pending.pop(0)

    def sin(self, angle, name, quarters=0):
        return sine_read(self.m, self.pipe, self._port(), angle, self.cfg, name,
                         near=self.near, line=self.line, quarters=quarters)

    def cos(self, angle, name):
        return self.sin(angle, name, quarters=1)                # cos a = sin(a + 90 deg)


def rotation_latency(cfg: Config):
    """Stages of :class:`ExactRotation` (and ``pipeline.VectorTerms``, in lock step beside
    it): the input sums, ``SineBank.latency``, three adder levels (pairs; the pairs of
    pairs, the doubled term copied beside them; their weighted sum: one carry chain a
    level), the output register (a plain copy of the third level, which feeds every
    light's illumination: the adders' route does not cross to them in the cycle that
    sums)."""
    return 1 + registered_sine_latency(cfg) + 4


def vector_terms(pipe, bank, vec, n_phi, name, latency):
    """The per-vector half of the exact rotation for a vector A = ``vec`` (polar angles):
    D = ph_A - ph_N, X = th_A + D, Y = th_A - D,
      2p = s(X) + s(Y), 2y = c(Y) - c(X), z = c(th_A)
    read from ``bank`` (a :class:`SineBank`) and delayed to ``latency`` pipe stages
    after the input. Shared by :class:`ExactRotation` and ``pipeline.VectorTerms``, so units
    built from it run in lock step."""
    bits = bank.cfg.angle_bits                          # binary angles wrap (mod 2**bits)
    d = pipe.register((vec.phi - n_phi)[:bits], f"{name}_d")             # input stage
    th = pipe.register(vec.theta, f"{name}_th")
    x, y = th + d, th - d
    terms = {"p2": bank.sin(x, f"{name}_sx") + bank.sin(y, f"{name}_sy"),
             "y2": bank.cos(y, f"{name}_cy") - bank.cos(x, f"{name}_cx"),
             "z": bank.cos(th, f"{name}_cth")}
    return {k: pipe.delay(v, latency - 1 - bank.latency, f"{name}_{k}")
            for k, v in terms.items()}


class ExactRotation(PipeUnit):
    """VectorRotation datapath, exact method (``rotation.VectorRotation`` with
    ``method = "exact"``; a ``wiring.Component``, rtl/methods.py's registry entry).

    Input ``pixel_layout(cfg)``; output :func:`rotated_layout`. With a = th_N' + ph_N',
    b = th_N' - ph_N', t = th_N:
      4 n''x = s(a+t) + s(a-t) + s(b+t) + s(b-t) + 2[s(t+th_N') + s(t-th_N')]
      2 n''y = c(b) - c(a)
      4 n''z = -[c(a-t) - c(a+t) + c(b-t) - c(b+t)] + 2[c(th_N'-t) + c(th_N'+t)]
    and per vector A: D = ph_A - ph_N, X = th_A + D, Y = th_A - D,
      2p = s(X) + s(Y), 2y = c(Y) - c(X), z = c(th_A).
    Latency :func:`rotation_latency`: the input sums (a, b, D), SineBank.latency (read
    angle, folded index, ROM address, its near copy, ROM read, block-RAM output register,
    data register, its copy, sign), three adder levels, the output register; 1 pixel per clock.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        self.latency = rotation_latency(cfg)
        super().__init__(cfg, pixel_layout(cfg), rotated_layout(cfg), target, credit, fifo_depth)

    def build(self, m, pipe):
        cfg = self.cfg
        rom = SineBank(m, pipe, cfg)
        px, o = self.i.payload, pipe.o.payload
        t, bt, bp = px.n.theta, px.b.theta, px.b.phi
        bits = cfg.angle_bits                  # input stage: a, b registered (mod 2**bits)
        a, b = pipe.register((bt + bp)[:bits], "a"), pipe.register((bt - bp)[:bits], "b")
        t, bt = pipe.register(t, "t"), pipe.register(bt, "bt")
        s = {f"s{n}": rom.sin(x, f"n_s{n}") for n, x in
             enumerate((a + t, a - t, b + t, b - t, t + bt, t - bt))}
        c = {f"c{n}": rom.cos(x, f"n_c{n}") for n, x in
             enumerate((b, a, a - t, a + t, b - t, b + t, bt - t, bt + t))}
        # Three adder levels, each registered and each one carry chain: pairs, then the
        # pairs of pairs (the doubled pair copied beside them), then the weighted sum.
        reg = pipe.register
        x = [reg(s["s0"] + s["s1"], "x4_a"), reg(s["s2"] + s["s3"], "x4_b"), reg(s["s4"] + s["s5"], "x4_c")]
        z = [reg(c["c2"] - c["c3"], "z4_a"), reg(c["c4"] - c["c5"], "z4_b"), reg(c["c6"] + c["c7"], "z4_c")]
        x01, x2 = reg(x[0] + x[1], "x4_ab"), reg(x[2], "x4_c2")
        z01, z2 = reg(z[0] + z[1], "z4_ab"), reg(z[2], "z4_c2")
        sums = {"x4": x01 + 2 * x2,
                "y2": reg(reg(c["c0"] - c["c1"], "y2_a"), "y2_a2"),
                "z4": 2 * z2 - z01}
        for name, value in sums.items():
            m.d.comb += o.n[name].eq(reg(reg(value, f"n_{name}_sum"), f"n_{name}"))
        for v in vectors(cfg):
            for name, value in vector_terms(pipe, rom, px[v], px.n.phi, v, self.latency).items():
                m.d.comb += o[v][name].eq(value)
        m.d.comb += o.tag.eq(pipe.delay(px.tag, self.latency, "tag"))


class ExactIllumination(IlluminationDatapath):
    """Illumination datapath, exact method: N'.A' = (x4 p2 + 2 y2 y2 + 2 z4 z) / 8, rounded
    once, then the shared back end (diffuse, cos^n specular table, Phong sum of eq. 2).

    Input :func:`rotated_layout`; output ``shade_layout(cfg)``.
    Latency: the products (PRODUCT_LATENCY: operand and product registers; with B > 13 an
    operand, n''x4 of B + 5 bits, is wider than one 18 x 18 DSP input and every product is a
    ``pipe.WideProduct``, WIDE_PRODUCT_LATENCY, on every target) + 2 (sum, rounding) +
    SHADE_LATENCY; 1 pixel per clock.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        super().__init__(cfg, rotated_layout(cfg), target, credit, fifo_depth)

    @property
    def wide(self):
        """The products' operands outgrow one DSP input (rotated_layout: n.x4 is the widest)."""
        layout = rotated_layout(self.cfg)
        return not fits_dsp(layout["n"].shape["x4"].shape, layout["l"].shape["p2"].shape)

    @property
    def dot_latency(self):
        return (WIDE_PRODUCT_LATENCY if self.wide else PRODUCT_LATENCY) + 2

    def dots(self, m, pipe, payload):
        n, dots = payload.n, {}
        mul = pipe.wide_multiply if self.wide else pipe.multiply
        for v in vectors(self.cfg):
            a = payload[v]
            xp = mul(n.x4, a.p2, f"{v}_xp")                            # 3 multipliers per vector
            yy = mul(n.y2, a.y2, f"{v}_yy")
            zz = mul(n.z4, a.z, f"{v}_zz")
            # round_shift(xp + 2 yy + 2 zz, B + 3) in two carry-chain stages: the rounding
            # half rides with 2 zz, so each stage adds two operands.
            n_shift = self.cfg.frac_bits + 3
            pair = pipe.register(xp + 2 * yy, f"{v}_xp_yy")
            zz_half = pipe.register(2 * zz + (1 << (n_shift - 1)), f"{v}_zz_half")
            dots[v] = pipe.register((pair + zz_half) >> n_shift, f"{v}_dot")
        return dots
