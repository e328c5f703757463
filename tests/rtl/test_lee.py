"""The lee datapaths (rtl/lee.py): ROM contents, structure against the paper's counts,
latency, a tiny configuration walked exhaustively against sim/golden/fixed/lee.py, emission.

The method-parametrized suites run the rest for lee as well, so it is not repeated here:
tests/rtl/test_rotation.py (the edge cases and 1 000 random vectors under every traffic
pattern, the tiny configuration, other widths, specular off) and
tests/sim/tb/test_tb_datapath.py (cocotb on the emitted Verilog, Icarus and Verilator;
10^6 vectors on Verilator in `make regress`)."""

import numpy as np
import pytest
from amaranth.hdl import unsigned

from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.units import build_unit, emit_unit
from bumprtl.rtl import tables
from bumprtl.rtl.config import Config
from bumprtl.rtl.lee import (
    ROM_STAGES,
    SINE_STAGES,
    BlockROM,
    LeeIllumination,
    LeeRotation,
    ratio_index,
)
from bumprtl.rtl.pipe import PRODUCT_LATENCY, ROM_LATENCY, WIDE_PRODUCT_LATENCY
from bumprtl.rtl.shade import SHADE_LATENCY
from bumprtl.rtl.sincos import REGISTERED_SINE_LATENCY
from bumprtl.sim.amaranth_stream import assert_bit_exact, check_datapath, simulate_stream
from bumprtl.sim.ecp5 import ecp5_lockstep, enabled_delay
from bumprtl.sim.golden.fixed import lee as fixed_lee
from bumprtl.sim.golden.vectors import TINY, as_payloads, random_codes

# --- ROM contents (tables.py, Lee section) ----------------------------------------------------

@pytest.mark.parametrize("cfg", [Config(method="lee"), TINY.replace(method="lee"),
                                 Config(angle_bits=14, frac_bits=20)])
def test_tables_against_float(cfg):
    step = 2 * np.pi / cfg.full_circle                      # one binary-angle step, radians
    a = tables.lee_asin_index_bits(cfg)
    s = np.arange((1 << a) + 1) / (1 << a)
    assert np.all(np.abs(tables.lee_asin_table(cfg) * step - np.arcsin(s)) <= step / 2 + 1e-12)
    inv = tables.lee_reciprocal_table(cfg)
    top = (1 << tables.lee_reciprocal_bits(cfg)) - 1
    assert inv[0] == top and inv[1] < top                   # only 1/sin 0 saturates (erratum 8)
    angles = np.arange(1, cfg.sincos_depth) * (np.pi / 2) / (1 << cfg.k)
    assert np.all(np.abs(inv[1:] - cfg.one / np.sin(angles)) <= 0.5 + 1e-9)
    p = tables.lee_prop_index_bits(cfg)
    y = np.arange((1 << p) + 1) / (1 << p)
    prop = tables.lee_prop_table(cfg) / cfg.one
    assert prop[0] == 0.0 and prop[-1] == 1.0 and np.all(np.diff(prop) >= 0)
    assert np.all(np.abs(prop - (1 - np.arccos(y) / (np.pi / 2))) <= 0.5 / cfg.one + 1e-12)


# every ratio of the tiny and the 8-bit configuration in make test; the default's 2**W
# ratios (a million) in make regress
@pytest.mark.parametrize("cfg", [pytest.param(Config(method="lee"), marks=pytest.mark.regress),
                                 TINY.replace(method="lee"), Config(angle_bits=8, frac_bits=7)])
def test_atan_address_and_table(cfg):
    """Every ratio p < 2**W (k fractional bits) gets an address whose entry is atan(p / 2**k)
    within half an angle step plus the mantissa's error 2**-(M+2) rad; the address is
    monotone, and its exponent is the leading-one position (checked with int.bit_length)."""
    w, m = tables.lee_atan_ratio_bits(cfg), tables.lee_atan_mantissa_bits(cfg)
    p = np.arange(1 << w, dtype=np.int64)
    index = ratio_index(p, cfg)
    assert index.max() == tables.lee_atan_depth(cfg) - 1 and np.all(np.diff(index) >= 0)
    sample = p[:: max(1, len(p) // 5000)]
    expect = [max(0, int(v).bit_length() - m - 1) for v in sample]
    assert np.array_equal(np.maximum((ratio_index(sample, cfg) >> m) - 1, 0), expect)
    step = 2 * np.pi / cfg.full_circle
    atan = tables.lee_atan_table(cfg)[index] * step
    exact = np.arctan((p + 0.5) / (1 << cfg.k))             # the floor of the pre-shift: +0.5
    assert np.max(np.abs(atan - exact)) <= step / 2 + 2.0 ** -(m + 2) + 1e-12


# --- structure against the paper --------------------------------------------------------------

def _memories(unit, cfg):
    _, sidecar, _ = build_unit(unit, cfg)
    return sidecar.roms


def test_rom_count_matches_table_1():
    """Fig. 7: six tables per vector (sin & cos, asin, 1/sin, 1/cos, atan, T_prop) -> Table 1's
    12 for L and H; Fig. 8: six cosine tables plus the specular table. Without specular the
    H sub-datapaths (and their tables) are not built."""
    cfg = Config(method="lee")
    roms = _memories("rotation", cfg)
    kinds = ("sincos", "asin", "inv_sin", "inv_cos", "atan", "prop")
    assert sorted(roms) == sorted(f"{v}_{kind}_rom" for v in "lh" for kind in kinds)
    assert len(_memories("rotation", cfg.replace(specular=False))) == 6
    ill = _memories("illumination", cfg)
    cosines = [name for name in ill if "_cos_" in name]
    assert len(cosines) == 6 and len(ill) == 7


def test_latency_and_one_pixel_per_clock():
    """Without stalls N pixels take N cycles plus the latency property."""
    cfg = Config(method="lee")
    codes = random_codes(300, cfg, seed=5)
    rot_cycles, ill_cycles = check_datapath(cfg, codes, "no_stall")
    assert rot_cycles == ill_cycles == 300


@pytest.mark.parametrize("cfg, prop, dot, rotation, illumination", [
    (Config(angle_bits=12, frac_bits=12), PRODUCT_LATENCY, PRODUCT_LATENCY, 35, 27),
    (Config(frac_bits=13), PRODUCT_LATENCY, PRODUCT_LATENCY, 35, 27),
    (Config(), PRODUCT_LATENCY, PRODUCT_LATENCY, 35, 27),
    (Config(angle_bits=13, frac_bits=16), PRODUCT_LATENCY, WIDE_PRODUCT_LATENCY, 35, 30),
    (Config(angle_bits=16, frac_bits=24), WIDE_PRODUCT_LATENCY, WIDE_PRODUCT_LATENCY, 38, 30)],
    ids=["a12b12", "b13", "default", "a13b16", "a16b24"])
def test_latencies_follow_the_product_widths(cfg, prop, dot, rotation, illumination):
    """A product whose operands outgrow one 18-bit DSP input is a WideProduct, three stages
    more: eq. 19's (90 - |Z|, angle_bits + 3 bits, x T_prop, B + 1 bits) from angle_bits 16
    or B = 17, eq. 24's (c- - c+, B + 3 bits, x c_phi) from B = 16."""
    cfg = cfg.replace(method="lee")
    rot, ill = LeeRotation(cfg), LeeIllumination(cfg)
    for unit in (rot, ill):
        unit._MustUse__silence = True          # read for its latency only, never elaborated
    assert (rot.latency, ill.latency) == (rotation, illumination)
    assert rot.latency == SINE_STAGES + 8 + 3 * ROM_STAGES + WIDE_PRODUCT_LATENCY + prop
    assert ill.latency == REGISTERED_SINE_LATENCY + dot + 2 + SHADE_LATENCY


# --- bit-exact against the golden model -----------------------------------------------------

def _class_walk(cfg):
    """4 096 vectors: each vector's rotation output depends on (th_N, ph_A - ph_N, th_A) only
    (tests/sim/golden/fixed/test_lee.py checks that on all 16^4 inputs), and L and H walk all
    16^3 such triples at once; N' walks all 16^2 values."""
    idx = np.arange(16 ** 3, dtype=np.int64)
    t, u, w = idx & 15, (idx >> 4) & 15, idx >> 8
    n_phi = (idx * 7 + w) & 15
    return {"n.phi": n_phi, "n.theta": t, "l.phi": (n_phi + u) & 15, "l.theta": w,
            "h.phi": (n_phi + w) & 15, "h.theta": u, "b.phi": u, "b.theta": w}


def test_tiny_config_exhaustive_classes():
    """k = 2: rotation over every (th_N, D, th_A) of both vectors, and illumination over every
    (th_A', th_N', ph_A' - ph_N') of both vectors (inputs fed directly, not only reachable ones)."""
    cfg = TINY.replace(method="lee")
    codes = _class_walk(cfg)
    inputs = as_payloads(codes, cfg)
    out, _ = simulate_stream(LeeRotation(cfg), inputs, "no_stall")
    assert_bit_exact(out, fixed_lee.rotation_fixed(codes, cfg), inputs)
    idx = np.arange(16 ** 3, dtype=np.int64)
    t, u, w = idx & 15, (idx >> 4) & 15, idx >> 8
    b_phi = (idx * 5 + t) & 15
    rot = {"l.phi": (b_phi + u) & 15, "l.theta": w, "h.phi": (b_phi + w) & 15, "h.theta": u,
           "b.phi": b_phi, "b.theta": t}
    inputs = as_payloads(rot, cfg)
    out, _ = simulate_stream(LeeIllumination(cfg), inputs, "backpressure", pipe_handshake=True)
    assert_bit_exact(out, fixed_lee.illumination_fixed(rot, cfg), inputs)


@pytest.mark.regress
def test_tiny_config_exhaustive_all_inputs():
    """k = 2: all 16^4 (ph_N, th_N, ph_A, th_A) for L (H and N' permuted), no equivalence
    argument needed; and all 16^4 (ph_A', th_A', ph_N', th_N') of the illumination."""
    cfg = TINY.replace(method="lee")
    idx = np.arange(16 ** 4, dtype=np.int64)
    d = [(idx >> (4 * j)) & 15 for j in range(4)]
    codes = {"n.phi": d[0], "n.theta": d[1], "l.phi": d[2], "l.theta": d[3],
             "h.phi": d[3], "h.theta": d[0], "b.phi": d[2], "b.theta": d[1]}
    inputs = as_payloads(codes, cfg)
    out, _ = simulate_stream(LeeRotation(cfg), inputs, "no_stall")
    assert_bit_exact(out, fixed_lee.rotation_fixed(codes, cfg), inputs)
    rot = {"l.phi": d[0], "l.theta": d[1], "h.phi": d[1], "h.theta": d[2], "b.phi": d[2],
           "b.theta": d[3]}
    inputs = as_payloads(rot, cfg)
    out, _ = simulate_stream(LeeIllumination(cfg), inputs, "no_stall")
    assert_bit_exact(out, fixed_lee.illumination_fixed(rot, cfg), inputs)


# --- ECP5 forms of the wide tables and products (placed by bumprtl report fpga) ---------------

@pytest.mark.parametrize("depth, width, ports", [(4097, 11, 1), (1025, 23, 3)])
def test_block_rom_ecp5_form(depth, width, ports, build_dir):
    """BlockROM's DP16KD form (x4 mode, 3 blocks, last word in a flip-flop; x18 mode, two
    blocks wide, two groups of ports, a non-zero word 0) reads as its generic form and the
    table, ROM_LATENCY enabled clocks later, under a random enable: every word once, then
    random addresses on every port."""
    rng = np.random.default_rng(depth + ports)
    init = rng.integers(0, 1 << width, depth).tolist()
    n = depth + 300
    en = (rng.random(n) < 0.8).astype(int)
    addrs = [rng.integers(0, depth, n) for _ in range(ports)]
    addrs[-1][:depth] = np.arange(depth)
    abits = (depth - 1).bit_length()
    inputs = {"rom_en": (1, en), **{f"rom_p{i}_addr": (abits, a) for i, a in enumerate(addrs)}}
    outputs = {f"rom_p{i}_data": width for i in range(ports)}
    forms = ecp5_lockstep(lambda t: BlockROM(init, unsigned(width), ports, "rom", target=t),
                          inputs, outputs, build_dir,
                          ports=lambda u: [u.en] + [s for p in u.ports for s in (p.addr, p.data)])
    for i, a in enumerate(addrs):
        want = enabled_delay([init[x] for x in a], en, ROM_LATENCY - 1)
        filled = [c for c in range(n) if want[c] is not None]
        for form in forms:
            assert [form[f"rom_p{i}_data"][c] for c in filled] == [want[c] for c in filled]


# --- emission and cocotb on the emitted Verilog ----------------------------------------------

@pytest.mark.parametrize("unit, widths", [
    ("rotation", {"angle_bits": 10, "frac_bits": 11}), ("illumination", {}),
    pytest.param("rotation", {}, marks=pytest.mark.regress)])
def test_emitted_verilog_lint_clean(unit, widths, build_dir):
    """Lint-clean at the default widths; the rotation's twelve ROMs at 10-bit angles in make
    test (the default widths' in make regress: 2049-word ROMs triple the lint time)."""
    cfg = Config(method="lee", **widths)
    v, j = emit_unit(unit, cfg, build_dir)
    assert lint(v) == []
    assert v.read_text().splitlines()[0].find("--method lee") > 0   # the command that made it
    assert f"--angle-bits {cfg.angle_bits} --frac-bits {cfg.frac_bits}" in v.read_text().splitlines()[0]


def test_widest_config_bit_exact_on_stress_cases():
    """angle_bits 16, frac_bits 24: |y2| x 1/|sin Z| needs k + 2B + 1 = 63 bits, past int64;
    the golden model must still match the RTL (exact widths) on every stress case,
    grid extremes included (the IndexError of docs/stability.md's first run)."""
    from bumprtl.sim.golden.stress import stress_codes
    cfg = Config(method="lee", angle_bits=16, frac_bits=24, spec_index_bits=16)
    check_datapath(cfg, stress_codes(180, cfg, seed=3), "no_stall")
