"""Peercy, Airey and Cabral 1997 in hardware: the Cartesian reference-space baseline of Lee
et al. Table 1 (first column), at the same Config widths as ours. Bit-exact with
``sim/golden/fixed/peercy.py``.

Inputs are Cartesian, as a Phong rasterizer's interpolators deliver them: the tangent frame
rows T, B, N, the light vector L, the halfway vector H (with ``cfg.specular``) and the
stored perturbed normal N' from the bump map, every component signed with ``frac_bits`` = B
fractional bits in ``B + 2`` bits (the sin/cos format of docs/architecture.md, Number formats; range [-2, 2)).

Setup (:class:`PeercyRotation`, Table 1's "illumination environment setup"), per vector A in {L, H}:

1. transform into the tangent space, A_t = (T.A, B.A, N.A): 9 multipliers, 6 adders, one
   rounding back to B fractional bits per component;
2. normalization, A_n = A_t / |A_t|: 3 multipliers (squares) and 2 adders for
   s = |A_t|**2 (2B fractional bits), one square root r = isqrt(4 s) = floor(2 |A_t| 2**B)
   (B + 1 fractional bits; the :class:`PeercySqrt` submodule ``{a}_sqrt``, a combinational
   restoring square root), and 3 dividers q = floor(|a| 2**(B+2) / r) on magnitudes (one
   extra quotient bit), then round half up q' = (q + 1) >> 1 (a constant adder, exactly
   the rounded quotient) and the sign of a put back (round half away from zero, so the
   normalization is odd-symmetric). A zero vector gives r = 0 and a zero quotient
   (Amaranth defines x // 0 = 0; the golden model does the same).

Counts for L and H: 24 multipliers (18 transform + 6 squares), 16 adders (12 + 4), 2 square
roots, 6 dividers. The paper counts 27 multipliers, 18 adders, 3 square roots and 9
division units: its normalization numbers are three vectors' worth (9 = 3 x 3 squares,
6 = 3 x 2 adders, 3 = 3 x 1 sqrt, 9 = 3 x 3 divisions) while only the transformed L and H
need normalizing here (N' comes unit-length from the bump map), so we build two vectors'
worth: per normalized vector 3 multipliers, 2 adders, 1 square root, 3 dividers, exactly the
paper's per-vector unit. Sign handling (|a|, -q') and the rounding constants are constant
adders, which the paper does not count.

Widths hold every input code without wrap-around: |T.A| <= 3 * 2**(2B+2) before rounding,
so a transformed component needs signed(B + 5) (18 bits at B = 13: one 18x18 DSP per
square), s < 2**(2B+9), r < 2**(B+6), and |q'| <= sqrt(2) 2**B + 1 (2|a|/r <= 2 sqrt(s) /
floor(2 sqrt(s)) <= sqrt 2 for s >= 1), which fits the signed(B + 2) output.

Timing: every product is a ``StallPipe.multiply`` (operand and product registers, one
MULT18X18D on ECP5 when both operands fit 18 bits: all 30 of them at B = 13). The square
root and the dividers are combinational, each alone between two registers: Yosys must see a
``$div`` cell to count a divider, so they are not hand-pipelined, and they set this unit's
Fmax, which is part of the baseline's cost.

Illumination (:class:`PeercyIllumination`): N'.L_n and N'.H_n (6 multipliers, 4 adders, one
rounding each), then the shared Phong back end of eq. (2) with the same cos^n specular
(power) table as ours (rtl/shade.py ``shade_stages``), so outputs are comparable.
The paper gives no illumination row for Peercy ("Not Available"); this is Ernst's
"straightforward Phong" (rtl/baselines/ernst.py), used for Peercy too.
"""

from amaranth.hdl import Cat, Const, Elaboratable, Module, Mux, Signal, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.pipe import PRODUCT_LATENCY, PipeUnit
from bumprtl.rtl.shade import IlluminationDatapath

__all__ = ["PeercyRotation", "PeercyIllumination", "PeercySqrt", "vectors", "cartesian_layout",
           "setup_input_layout", "setup_output_layout", "component_width", "square_bits",
           "ROTATION_LATENCY", "DOT_LATENCY"]

AXES = ("x", "y", "z")
FRAME = ("t", "b", "n")       # tangent, binormal, normal: the rows of the 3x3 transform
# Registers of the setup: products (PRODUCT_LATENCY: operand and product registers, one
# DSP block on ECP5), transformed sums, squares (PRODUCT_LATENCY; |a| rides along),
# |A_t|**2, square root, quotient, signed result.
ROTATION_LATENCY = 2 * PRODUCT_LATENCY + 5
DOT_LATENCY = PRODUCT_LATENCY + 1     # products, sum (then rtl/shade.SHADE_LATENCY)


def vectors(cfg: Config):
    """The vectors transformed and normalized per pixel: L, and H with specular."""
    return ("l", "h") if cfg.specular else ("l",)


def cartesian_layout(cfg: Config):
    """A Cartesian vector: x, y, z signed with frac_bits fractional bits, B + 2 bits."""
    return data.StructLayout({a: signed(cfg.sincos_width) for a in AXES})


def setup_input_layout(cfg: Config):
    """Setup input: frame rows t, b, n, then l, h (with specular), np (N') and the tag."""
    fields = {name: cartesian_layout(cfg) for name in (*FRAME, *vectors(cfg), "np")}
    fields["tag"] = unsigned(cfg.tag_bits)
    return data.StructLayout(fields)


def setup_output_layout(cfg: Config):
    """Setup output = illumination input: normalized l, h (tangent space), np, tag."""
    fields = {name: cartesian_layout(cfg) for name in (*vectors(cfg), "np")}
    fields["tag"] = unsigned(cfg.tag_bits)
    return data.StructLayout(fields)


def component_width(cfg: Config):
    """Signed width of a transformed component rounded to B bits: |T.A| < 2**(B+4)."""
    return cfg.frac_bits + 5


def square_bits(cfg: Config):
    """Unsigned width of s = |A_t|**2 (2B fractional bits): s < 27 * 2**(2B+4) < 2**(2B+9)."""
    return 2 * cfg.frac_bits + 9


class PeercySqrt(Elaboratable):
    """Integer square root, ``root = floor(sqrt(radicand))``, combinational, restoring
    (one bit of the root per step: try (root << 2) | 1 against the remainder).

    Its Amaranth submodule name ends in ``sqrt`` so that gen/flow/resources.py keeps it as a
    black box and counts it as one square root (Table 1's "SQRt").
    """

    def __init__(self, width):
        self.width = width
        self.root_bits = (width + 1) // 2
        self.radicand = Signal(width)
        self.root = Signal(self.root_bits)

    def elaborate(self, platform):
        m = Module()
        n = self.root_bits
        w = n + 2                                 # the remainder stays <= 2 root < 2**(n+1)
        x = Cat(self.radicand, Const(0, 2 * n - self.width))
        rem, root = Const(0, w), Const(0, 0)
        for k in reversed(range(n)):
            # One named signal per step keeps the netlist (and the simulator) linear in n.
            rem4 = Cat(x[2 * k:2 * k + 2], rem)[:w]
            diff = Signal(w + 1, name=f"diff{k}")
            m.d.comb += diff.eq(rem4 - Cat(Const(1, 2), root))    # borrow in the top bit
            fits = ~diff[-1]
            rem = Signal(w, name=f"rem{k}")
            m.d.comb += rem.eq(Mux(fits, diff[:w], rem4))
            root = Cat(fits, root)
        m.d.comb += self.root.eq(root)
        return m


class PeercyRotation(PipeUnit):
    """Setup datapath, Peercy (``rotation.VectorRotation`` with ``method = "peercy"``; a
    ``wiring.Component``).

    Input :func:`setup_input_layout`; output :func:`setup_output_layout` (L_n, H_n in tangent
    space, N' passed through). Latency :data:`ROTATION_LATENCY` (2 PRODUCT_LATENCY + 5 = 9);
    1 pixel per clock.
    """

    latency = ROTATION_LATENCY

    def __init__(self, cfg: Config, target=None):
        super().__init__(cfg, setup_input_layout(cfg), setup_output_layout(cfg), target)

    def build(self, m, pipe):
        cfg, b = self.cfg, self.cfg.frac_bits
        reg = pipe.register
        px, out = self.i.payload, self.o.payload
        cw = component_width(cfg)
        for v in vectors(cfg):
            a = px[v]
            comps = {}
            for row, axis in zip(FRAME, AXES):             # A_t = (T.A, B.A, N.A)
                p = [pipe.multiply(px[row][c], a[c], f"{v}_{row}{c}") for c in AXES]  # + P
                comps[axis] = reg(round_shift(p[0] + p[1] + p[2], b)[:cw].as_signed(),
                                  f"{v}t_{axis}")                                    # + 1
            sq = [pipe.multiply(comps[c], comps[c], f"{v}t_{c}_sq") for c in AXES]   # + P
            mag = {c: pipe.delay(Mux(comps[c] < 0, -comps[c], comps[c])[:cw - 1],
                                 PRODUCT_LATENCY, f"{v}t_{c}_mag") for c in AXES}
            neg = {c: pipe.delay(comps[c][-1], PRODUCT_LATENCY + 3, f"{v}t_{c}_neg") for c in AXES}
            # x**2 >= 0 and < 2**(2B+8): the low 2B+8 bits of each signed square are exact
            sq = [q[:square_bits(cfg) - 1] for q in sq]
            s = reg(sq[0] + sq[1] + sq[2], f"{v}t_len2")                             # + 1
            m.submodules[f"{v}_sqrt"] = root = PeercySqrt(square_bits(cfg) + 2)
            m.d.comb += root.radicand.eq(s << 2)
            r = reg(root.root, f"{v}t_len")                                          # + 1
            for c in AXES:
                num = pipe.delay(mag[c], 2, f"{v}t_{c}_num") << (b + 2)
                q = reg(num // r, f"{v}n_{c}_q")                                     # + 1
                q = round_shift(q, 1)
                m.d.comb += out[v][c].eq(reg(Mux(neg[c], -q, q)[:cfg.sincos_width],
                                             f"{v}n_{c}"))                           # + 1
        for c in AXES:
            m.d.comb += out.np[c].eq(pipe.delay(px.np[c], self.latency, f"np_{c}"))
        m.d.comb += out.tag.eq(pipe.delay(px.tag, self.latency, "tag"))


class PeercyIllumination(IlluminationDatapath):
    """Illumination datapath, Peercy (and Ernst): N'.A_n = round((N'.A_n) / 2**B) per
    vector (3 multipliers, 2 adders), then the shared back end (diffuse, cos^n specular
    table, Phong sum of eq. 2).

    Input :func:`setup_output_layout`; output ``shade_layout(cfg)``.
    Latency PRODUCT_LATENCY (operand and product registers) + 1 (sum) + SHADE_LATENCY;
    1 pixel per clock.
    """

    dot_latency = DOT_LATENCY

    def __init__(self, cfg: Config, target=None):
        super().__init__(cfg, setup_output_layout(cfg), target)

    def dots(self, m, pipe, payload):
        n, dots = payload.np, {}
        for v in vectors(self.cfg):
            a = payload[v]
            p = [pipe.multiply(n[c], a[c], f"{v}_dot_{c}") for c in AXES]            # + P
            dots[v] = pipe.register(round_shift(p[0] + p[1] + p[2], self.cfg.frac_bits),
                                    f"{v}_dot")                                      # + 1
        return dots
