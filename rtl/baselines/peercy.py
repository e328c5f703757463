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
   (B + 1 fractional bits; the :class:`PeercySqrt` submodule ``{a}_sqrt``), and 3 dividers
   q = floor(|a| 2**(B+2) / r) on magnitudes (one extra quotient bit; the
   :class:`PeercyDivider` submodules ``{a}_{x,y,z}_div``), then round half up
   q' = (q + 1) >> 1 (a constant adder, exactly the rounded quotient) and the sign of a put
   back (round half away from zero, so the normalization is odd-symmetric). A zero vector
   gives r = 0 and a zero quotient (Amaranth defines x // 0 = 0; the golden model and the
   divider do the same).

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

Timing: every product is a ``Pipe.multiply`` (operand and product registers, one
MULT18X18D on ECP5) when both operands fit one 18-bit DSP input (all 30 of them at B = 13),
else a ``Pipe.wide_multiply`` (a ``pipe.WideProduct``: on ECP5 17-bit limbs, one
MULT18X18D per pair, their sum in two registers of its own), two stages more on every
target: the squares of the (B + 5)-bit components from B = 14, the transform and the dots of
the (B + 2)-bit inputs from B = 17 (:func:`product_latencies`). The square root and the
dividers are pipelined by hand, one result bit per stage with a register after each, every
register enabled by the pipe's ``en`` (the constant 1) (B. Parhami, Computer Arithmetic: Algorithms and
Hardware Designs, ch. 13, restoring division, and ch. 21, the restoring shift/subtract
square root): :func:`sqrt_stages` = B + 6 stages of at most a (B + 8)-bit subtractor,
:func:`quotient_bits` = B + 2 stages of a (B + 7)-bit one. B + 2 quotient bits are exact:
r = isqrt(4 s) >= isqrt(4 a**2) = 2 |a|, so q <= 2**(B+1). Each is a submodule whose name
ends in ``sqrt`` or ``_div``, which gen/flow/resources.py keeps as a black box and counts as
one square root or one divider (Table 1's "SQRt" and "division units"). Latency
:func:`rotation_latency` (43 at B = 13, 52 at B = 16); 1 pixel per clock. Every sum of three
products (the transform and the dots N'.A_n, :func:`sum3_rounded`, and |A_t|**2) is two
registered 2-operand adders, not one 3-operand adder behind the DSP blocks' outputs.

Illumination (:class:`PeercyIllumination`): N'.L_n and N'.H_n (6 multipliers, 4 adders, one
rounding each), then the shared Phong back end of eq. (2) with the same cos^n specular
(power) table as ours (rtl/shade.py ``shade_stages``), so outputs are comparable.
The paper gives no illumination row for Peercy ("Not Available"); this is Ernst's
"straightforward Phong" (Ernst is an alias of this hardware, rtl/methods.py), used for Peercy too.
"""

from amaranth.hdl import Cat, Const, Elaboratable, Module, Mux, Signal, Value, signed, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.fixed import round_shift
from bumprtl.rtl.pipe import PipeUnit, product_latency
from bumprtl.rtl.shade import IlluminationDatapath

__all__ = ["PeercyRotation", "PeercyIllumination", "PeercySqrt", "PeercyDivider", "vectors",
           "cartesian_layout", "setup_input_layout", "setup_output_layout", "component_width",
           "square_bits", "sqrt_stages", "quotient_bits", "product_latencies",
           "rotation_latency", "dot_latency", "sum3_rounded"]

AXES = ("x", "y", "z")
FRAME = ("t", "b", "n")       # tangent, binormal, normal: the rows of the 3x3 transform


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


def sqrt_stages(cfg: Config):
    """Stages of the square root of 4 s (2B + 11 bits): one per root bit, B + 6."""
    return (square_bits(cfg) + 3) // 2


def quotient_bits(cfg: Config):
    """Quotient bits (= divider stages) of q = floor(|a| 2**(B+2) / r) <= 2**(B+1): B + 2."""
    return cfg.frac_bits + 2


def _operands(cfg: Config):
    """Operand shapes: "product" (the transform and the dots: two input components, B + 2
    bits) and "square" (a transformed component, :func:`component_width`)."""
    return {"product": (signed(cfg.sincos_width),) * 2,
            "square": (signed(component_width(cfg)),) * 2}


def product_latencies(cfg: Config):
    """Stages of the transform and dot products ("product") and of the squares ("square"):
    ``pipe.product_latency`` of their operands, PRODUCT_LATENCY when they fit one DSP input,
    else WIDE_PRODUCT_LATENCY."""
    return {name: product_latency(*shapes) for name, shapes in _operands(cfg).items()}


def rotation_latency(cfg: Config):
    """Registers of the setup: products (:func:`product_latencies`), transformed sums (2),
    squares (likewise; |a| rides along), |A_t|**2 (2), the square root's stages, the
    divider's stages, signed result."""
    lat = product_latencies(cfg)
    return lat["product"] + lat["square"] + 5 + sqrt_stages(cfg) + quotient_bits(cfg)


def dot_latency(cfg: Config):
    """Registers of the illumination's dots: products (:func:`product_latencies`), two sum
    stages (:func:`sum3_rounded`); then rtl/shade.SHADE_LATENCY."""
    return product_latencies(cfg)["product"] + 2


def sum3_rounded(reg, p, b, name):
    """round((p0 + p1 + p2) / 2**b) two ``reg`` stages later (``reg``: a Pipe's
    ``register``): one 2-operand carry chain a cycle, the rounding half of
    rtl/fixed.round_shift riding in the first, so three products leaving their DSP
    blocks are not summed in one cycle."""
    p01 = reg(p[0] + p[1] + (1 << (b - 1)), f"{name}_01")
    return reg((p01 + reg(p[2], f"{name}_2")) >> b, name)


def _stage(m, en, value, name):
    """``value`` through one register enabled by ``en`` (the enclosing pipe's ``en``, the constant 1)."""
    value = Value.cast(value)
    reg = Signal(value.shape(), name=name)
    with m.If(en):
        m.d.sync += reg.eq(value)
    return reg


class PeercySqrt(Elaboratable):
    """Integer square root, ``root = floor(sqrt(radicand))``, pipelined: radix-2 restoring,
    one bit of the root per stage (try (root << 2) | 1 against the remainder with the next
    two radicand bits shifted in; Parhami ch. 21), a register after each. ``root`` comes
    ``stages`` (= ``root_bits``) ``en`` cycles after ``radicand``; ``en`` is the enclosing
    pipe's ``en`` (the constant 1: the pipe never stops).

    Its Amaranth submodule name ends in ``sqrt`` so that gen/flow/resources.py keeps it as a
    black box and counts it as one square root (Table 1's "SQRt").
    """

    def __init__(self, width):
        self.width = width
        self.root_bits = self.stages = (width + 1) // 2
        self.radicand = Signal(width)
        self.en = Signal()
        self.root = Signal(self.root_bits)

    def elaborate(self, platform):
        m = Module()
        n = self.root_bits
        low = Cat(self.radicand, Const(0, 2 * n - self.width))   # radicand bits still to use
        rem, root = Const(0, 1), Const(0, 0)
        for k in reversed(range(n)):
            j = n - 1 - k                     # root bits so far: rem <= 2 root < 2**(j+1)
            rem4 = Cat(low[2 * k:2 * k + 2], rem)                    # j + 3 bits
            # rem4 - (4 root + 1) is in (-2**(j+2), 2**(j+2)): j + 3 bits, the borrow on top
            diff = Signal(j + 3, name=f"diff{k}")
            m.d.comb += diff.eq(rem4 - Cat(Const(1, 2), root))
            fits = ~diff[-1]
            root = _stage(m, self.en, Cat(fits, root), f"root{k}")
            if k:                             # the new remainder <= 2 root < 2**(j+2)
                rem = _stage(m, self.en, Mux(fits, diff[:j + 2], rem4[:j + 2]), f"rem{k}")
                low = _stage(m, self.en, low[:2 * k], f"radicand{k}")
        m.d.comb += self.root.eq(root)
        return m


class PeercyDivider(Elaboratable):
    """``quotient = floor(dividend / divisor)``, 0 for a zero divisor (Amaranth's ``//``),
    pipelined: restoring division, one quotient bit per stage, most significant first (the
    remainder with the next dividend bit shifted in, less the divisor if it fits; Parhami
    ch. 13), a register after each. ``quotient`` comes ``stages`` (= ``quotient_bits``)
    ``en`` cycles after the operands; ``en`` is the enclosing pipe's ``en`` (the constant 1).

    ``quotient_bits`` (default: the dividend's width, exact for every input) may be fewer
    when the caller knows ``dividend < divisor * 2**quotient_bits``; then the remainder stays
    below the divisor and every stage is a (divisor width + 1)-bit subtractor.

    Its Amaranth submodule name ends in ``_div`` so that gen/flow/resources.py keeps it as a
    black box and counts it as one divider (Table 1's "division unit"), listed by the widths
    of ``dividend`` and ``divisor``.
    """

    def __init__(self, dividend_bits, divisor_bits, quotient_bits=None):
        self.quotient_bits = self.stages = (dividend_bits if quotient_bits is None
                                            else quotient_bits)
        self.dividend = Signal(dividend_bits)
        self.divisor = Signal(divisor_bits)
        self.en = Signal()
        self.quotient = Signal(self.quotient_bits)

    def elaborate(self, platform):
        m = Module()
        nq, dw = self.quotient_bits, len(self.divisor)
        x = Cat(self.dividend, Const(0, max(0, nq - len(self.dividend))))
        rem, low = x[nq:nq + dw], x[:nq]      # dividend >> nq < divisor: the precondition
        d, zero, quo = self.divisor, ~self.divisor.any(), Const(0, 0)
        for i in reversed(range(nq)):
            t = Cat(low[i], rem)              # < 2 divisor, so t - divisor is in
            diff = Signal(dw + 1, name=f"diff{i}")    # (-2**dw, 2**dw): the borrow on top
            m.d.comb += diff.eq(t - d)
            fits = ~diff[-1] & ~zero
            quo = _stage(m, self.en, Cat(fits, quo), f"quotient{i}")
            if i:                             # the new remainder < divisor < 2**dw
                rem = _stage(m, self.en, Mux(fits, diff[:dw], t[:dw]), f"rem{i}")
                low = _stage(m, self.en, low[:i], f"dividend{i}")
                d = _stage(m, self.en, d, f"divisor{i}")
                zero = _stage(m, self.en, zero, f"zero{i}")
        m.d.comb += self.quotient.eq(quo)
        return m


class PeercyRotation(PipeUnit):
    """Setup datapath, Peercy (``rotation.VectorRotation`` with ``method = "peercy"``; a
    ``wiring.Component``).

    Input :func:`setup_input_layout`; output :func:`setup_output_layout` (L_n, H_n in tangent
    space, N' passed through). Latency :func:`rotation_latency` (the two products' stages
    + 5 + (B + 6) + (B + 2): 2 PRODUCT_LATENCY + 5 + 15 + 11 = 35 at B = 9,
    2 PRODUCT_LATENCY + 5 + 19 + 15 = 43 at B = 13, PRODUCT_LATENCY + WIDE_PRODUCT_LATENCY
    + 5 + 22 + 18 = 52 at B = 16); 1 pixel per clock.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        self.latency = rotation_latency(cfg)
        super().__init__(cfg, setup_input_layout(cfg), setup_output_layout(cfg), target, credit, fifo_depth)

    def build(self, m, pipe):
        cfg, b = self.cfg, self.cfg.frac_bits
        reg = pipe.register
        px, out = self.i.payload, pipe.o.payload
        cw, ns, nq = component_width(cfg), sqrt_stages(cfg), quotient_bits(cfg)
        ops, sq_lat = _operands(cfg), product_latencies(cfg)["square"]
        mul, square = pipe.multiplier(*ops["product"]), pipe.multiplier(*ops["square"])
        for v in vectors(cfg):
            a = px[v]
            comps = {}
            for row, axis in zip(FRAME, AXES, strict=False):             # A_t = (T.A, B.A, N.A)
                p = [mul(px[row][c], a[c], f"{v}_{row}{c}") for c in AXES]          # + P
                comps[axis] = sum3_rounded(reg, p, b, f"{v}t_{axis}")[:cw].as_signed()  # + 2
            sq = [square(comps[c], comps[c], f"{v}t_{c}_sq") for c in AXES]         # + P
            mag = {c: pipe.delay(Mux(comps[c] < 0, -comps[c], comps[c])[:cw - 1],
                                 sq_lat, f"{v}t_{c}_mag") for c in AXES}
            neg = {c: pipe.delay(comps[c][-1], sq_lat + 2 + ns + nq, f"{v}t_{c}_neg")
                   for c in AXES}
            # x**2 >= 0 and < 2**(2B+8): the low 2B+8 bits of each signed square are exact
            sq = [q[:square_bits(cfg) - 1] for q in sq]
            s = reg(reg(sq[0] + sq[1], f"{v}t_len2_xy") + reg(sq[2], f"{v}t_len2_z"),
                    f"{v}t_len2")                                                    # + 2
            m.submodules[f"{v}_sqrt"] = root = PeercySqrt(square_bits(cfg) + 2)
            m.d.comb += [root.radicand.eq(s << 2), root.en.eq(pipe.en)]
            r = root.root                                                            # + ns
            for c in AXES:
                num = pipe.delay(mag[c], 2 + ns, f"{v}t_{c}_num").shift_left(b + 2)
                m.submodules[f"{v}_{c}_div"] = div = PeercyDivider(len(num), len(r), nq)
                m.d.comb += [div.dividend.eq(num), div.divisor.eq(r), div.en.eq(pipe.en)]
                q = round_shift(div.quotient, 1)                                     # + nq
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
    Latency :func:`dot_latency` = the products' stages (PRODUCT_LATENCY, operand and product
    registers, up to B = 16; WIDE_PRODUCT_LATENCY beyond) + 2 (the sum,
    :func:`sum3_rounded`), then SHADE_LATENCY; 1 pixel per clock.
    """

    def __init__(self, cfg: Config, target=None, credit=True, fifo_depth=None):
        self.dot_latency = dot_latency(cfg)
        super().__init__(cfg, setup_output_layout(cfg), target, credit, fifo_depth)

    def dots(self, m, pipe, payload):
        n, dots = payload.np, {}
        mul = pipe.multiplier(*_operands(self.cfg)["product"])
        for v in vectors(self.cfg):
            a = payload[v]
            p = [mul(n[c], a[c], f"{v}_dot_{c}") for c in AXES]                      # + P
            dots[v] = sum3_rounded(pipe.register, p, self.cfg.frac_bits, f"{v}_dot")   # + 2
        return dots
