"""Peercy and Ernst baselines (rtl/baselines/peercy.py, ernst.py): the Amaranth simulator bit
for bit against sim/golden/fixed/peercy.py (random, edge, full-range and narrow/wide inputs,
with and without stalls), emission (lint-clean, deterministic, CLI) and the Yosys counts
against the structure. The pipelined square root and divider alone:
tests/rtl/test_baselines_arith.py."""

import subprocess
import sys

import numpy as np
import pytest

from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.resources import count_component, count_verilog, multiplier_pairs
from bumprtl.gen.flow.units import build_unit, emit_unit
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import EDGE_LATENCY, PRODUCT_LATENCY, WIDE_PRODUCT_LATENCY
from bumprtl.rtl.shade import SHADE_LATENCY, BackEnd
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.amaranth_stream import check_illumination, check_rotation
from bumprtl.sim.golden import methods
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed import peercy as fixed_peercy
from bumprtl.sim.golden.vectors import concat_codes, edge_codes
from bumprtl.sim.traffic import PATTERNS

METHODS = [n for n, m in methods.METHODS.items() if m.cartesian]     # peercy, ernst
NARROW = Config(method="peercy", angle_bits=8, frac_bits=9, tag_bits=12, spec_exponent=3)


def stimulus(cfg, n, seed):
    """The shared polar edge cases as Cartesian codes, then ``n`` random valid pixels."""
    edges = fixed_peercy.from_angle_codes(edge_codes(cfg), cfg)
    rand = fixed_peercy.encode(PixelInputs.random(n, np.random.default_rng(seed)), cfg)
    return concat_codes(edges, rand)


def full_range_codes(cfg, n, seed):
    """Any input code at all: uniform over the whole signed(B + 2) range, plus zero vectors
    and the most negative code everywhere (the widths must hold them without wrapping)."""
    rng = np.random.default_rng(seed)
    lo, hi = -(1 << (cfg.frac_bits + 1)), (1 << (cfg.frac_bits + 1)) - 1
    keys = fixed_peercy.input_keys(cfg)
    codes = {k: rng.integers(lo, hi + 1, n) for k in keys}
    for k in keys:
        codes[k][:3] = [0, lo, hi]
    return codes


# --- bit-exact in the Amaranth simulator -----------------------------------------------------

@pytest.mark.parametrize("method,n", [("peercy", 500)])
def test_bit_exact_no_stall_one_pixel_per_clock(method, n):
    """Edge cases + n random pixels (Ernst's datapath is Peercy's, rtl/methods.py: simulated
    once, as peercy; tests/rtl/test_methods.py checks the alias builds Peercy's classes)."""
    cfg = Config(method=method)
    codes = stimulus(cfg, n, seed=1)
    total = len(codes["l.x"])
    for run in (check_rotation, check_illumination):
        latency, cycles = run(cfg, codes, "no_stall")
        assert cycles == total + latency


# "both" (gaps and backpressure at once) in make test; each alone in make regress: the stall
# rule is the shared StallPipe's, which every unit's own tests run under all three.
@pytest.mark.parametrize("pattern", [p if p == "both" else pytest.param(p, marks=pytest.mark.regress)
                                     for p in PATTERNS if p != "no_stall"])
def test_bit_exact_under_stalls(pattern):
    cfg = Config(method="peercy")
    codes = stimulus(cfg, 200, seed=2)
    check_rotation(cfg, codes, pattern)
    check_illumination(cfg, codes, pattern)


def test_bit_exact_on_full_range_and_degenerate_inputs():
    """Non-unit, zero and extreme vectors: r = 0 gives a zero quotient in both models."""
    cfg = Config(method="peercy")
    codes = full_range_codes(cfg, 300, seed=3)
    check_rotation(cfg, codes, "backpressure")
    check_illumination(cfg, codes, "no_stall")


WIDE = Config(method="ernst", angle_bits=14, frac_bits=20, spec_exponent=128)


# each width with specular on and off between make test (the first two) and make regress
@pytest.mark.parametrize("cfg", [NARROW.replace(specular=False), WIDE,
                                 pytest.param(NARROW, marks=pytest.mark.regress),
                                 pytest.param(WIDE.replace(specular=False), marks=pytest.mark.regress)],
                         ids=["narrow-diffuse", "wide-specular", "narrow-specular", "wide-diffuse"])
def test_narrow_and_wide_configurations(cfg):
    codes = concat_codes(stimulus(cfg, 60, seed=4), full_range_codes(cfg, 40, seed=5))
    check_rotation(cfg, codes, "input_gaps")
    check_illumination(cfg, codes, "backpressure")


P, W = PRODUCT_LATENCY, WIDE_PRODUCT_LATENCY


@pytest.mark.parametrize("cfg, product, square, rotation_latency", [
    (NARROW, P, P, 35), (Config(frac_bits=13), P, P, 43), (Config(), P, W, 50),
    (Config(angle_bits=13, frac_bits=16), P, W, 52),
    (Config(angle_bits=14, frac_bits=20), W, W, 63)], ids=["narrow", "b13", "default", "b16", "b20"])
def test_latencies_follow_the_structure(cfg, product, square, rotation_latency):
    """Setup: the transform's products and the squares are registered products
    (PRODUCT_LATENCY while their operands, B + 2 and B + 5 bits, fit one 18-bit DSP input,
    else WideProducts, WIDE_PRODUCT_LATENCY), plus the transformed sum and |A_t|**2 (two
    2-operand adder stages each), the signed result, the square root's B + 6 stages (one per
    root bit of 4 s) and the divider's B + 2 (one per quotient bit). Illumination: the dot's
    products (as the transform's), its sum (two stages), then the shared back end."""
    b = cfg.frac_bits
    for method in METHODS:
        cfg = cfg.replace(method=method)
        rotation, illumination = (cls(cfg) for cls in (methods.get(method).rotation,
                                                       methods.get(method).illumination))
        for unit in (rotation, illumination):
            unit._MustUse__silence = True          # read for its latency only, never elaborated
        assert rotation.latency == product + square + 5 + (b + 6) + (b + 2) == rotation_latency
        assert illumination.latency == product + 2 + SHADE_LATENCY


# --- emission -------------------------------------------------------------------------------

@pytest.mark.parametrize("unit", ["illumination", pytest.param("rotation", marks=pytest.mark.regress)])
def test_emission_lint_clean_and_deterministic(unit, build_dir):
    cfg = Config(method="peercy")
    v1, j1 = emit_unit(unit, cfg, build_dir / "a")
    v2, j2 = emit_unit(unit, cfg, build_dir / "b")
    assert v1.read_bytes() == v2.read_bytes() and j1.read_bytes() == j2.read_bytes()
    assert "--method peercy" in v1.read_text().splitlines()[0]
    assert lint(v1) == []


# make regress: make test checks Ernst's sidecar and recorded command below
# (test_sidecar_of_ernst_names_its_method) and Peercy's setup, which is Ernst's, above
@pytest.mark.regress
def test_ernst_emits_the_same_setup_hardware(build_dir):
    """Ernst's setup is Peercy's: the same Verilog apart from the command in the header (at
    10-bit angles, B = 11: the structure does not depend on the widths)."""
    narrow = {"angle_bits": 10, "frac_bits": 11}
    vp, _ = emit_unit("rotation", Config(method="peercy", **narrow), build_dir / "p")
    ve, _ = emit_unit("rotation", Config(method="ernst", **narrow), build_dir / "e")
    assert vp.read_text().splitlines()[2:] == ve.read_text().splitlines()[2:]
    assert "--method ernst" in ve.read_text().splitlines()[0]


def test_cli_emit_rotation_method_peercy(tmp_path, run_cli):
    """The command line writes what emit_unit writes, byte for byte (deterministic across
    processes), and it is lint-clean. At 10-bit angles, B = 11 (make regress lints the
    default's setup, the test above)."""
    cfg = Config(method="peercy", angle_bits=10, frac_bits=11)
    r = subprocess.run([sys.executable, "-m", "bumprtl.gen.cli.main", "emit", "rotation", "--method",
                        "peercy", "--angle-bits", "10", "--frac-bits", "11", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    v, j = emit_unit("rotation", cfg, tmp_path / "api", module="bumprtl_rotation")
    assert v.read_bytes() == (tmp_path / "bumprtl_rotation.v").read_bytes()
    assert j.read_bytes() == (tmp_path / "bumprtl_rotation.json").read_bytes()
    assert lint(v) == []
    b = cfg.frac_bits
    assert (tmp_path / "bumprtl_rotation.v").read_text().startswith(
        f"// Generated by: bumprtl emit rotation --method peercy --angle-bits 10 --frac-bits {b}")
    meta = load_sidecar(tmp_path / "bumprtl_rotation.json")
    assert meta.method == "peercy"
    # products and squares (B + 2 and B + 5 bits: one DSP each at B = 11), sums, the square
    # root (B + 6 stages: a bit a stage) and the divider (B + 2)
    assert meta.latency == 2 * PRODUCT_LATENCY + 5 + (b + 6) + (b + 2) + EDGE_LATENCY
    assert meta.error_bounds.lsb == max(fixed_peercy.predicted_error_bound_lsb(cfg, c)
                                          for c in ("diffuse", "specular", "color"))
    assert sorted(meta.input_fields) == sorted(
        fixed_peercy.input_keys(cfg) + ["tag"])
    bad = run_cli(["emit", "rotation", "--method", "peercy", "--frac-bits", "40", "--out", tmp_path])
    assert bad.returncode == 2 and "frac_bits" in bad.stderr and "Traceback" not in bad.stderr


# --- Yosys counts against the structure (rtl/baselines/peercy.py docstring) -------------------

# with the H path in make test; without it (the same structure, one vector) in make regress
@pytest.mark.parametrize("specular", [True, pytest.param(False, marks=pytest.mark.regress)])
def test_setup_counts_match_the_structure(specular, build_dir):
    """Per normalized vector: 9 transform products of two signed(B + 2) inputs and 3 squares
    of signed(B + 5) components; 6 + 2 adders; one square root; 3 dividers of |a| 2**(B+2)
    (B + 4 + B + 2 bits) by r (B + 6 bits). No tables. With L and H: 24 multipliers,
    16 adders, 2 square roots, 6 dividers (Table 1: 27, 18, 3, 9 for three vectors)."""
    cfg = NARROW.replace(specular=specular)
    b, nvec = cfg.frac_bits, 2 if specular else 1
    v_path, _ = emit_unit("rotation", cfg, build_dir)
    c = count_verilog(v_path, "rotation", build_dir / "yosys")
    expected = [(b + 2, b + 2)] * (9 * nvec) + [(b + 5, b + 5)] * (3 * nvec)
    assert multiplier_pairs(c.multipliers) == sorted(expected)
    assert len(c.adders) == 8 * nvec
    assert c.sqrts == nvec
    assert sorted(c.dividers) == [f"{2 * b + 6}/{b + 6}"] * (3 * nvec)
    assert c.tables == [] and c.const_multipliers == []


def test_illumination_counts_are_the_back_end_plus_two_dots(build_dir):
    """N'.L_n and N'.H_n: 3 products of signed(B + 2) values and 2 adders each; the rest
    (Phong weights, power table, Phong sum) is the shared back end, counted on its own."""
    cfg = NARROW.replace(method="ernst")
    q = cfg.frac_bits + 2
    v_path, _ = emit_unit("illumination", cfg, build_dir)
    c = count_verilog(v_path, "illumination", build_dir / "yosys")
    shade = count_component(BackEnd(cfg), "shade_only", build_dir / "shade")
    assert multiplier_pairs(c.multipliers) == multiplier_pairs(
        shade.multipliers + [f"{q}x{q}"] * 6)
    assert len(c.adders) == len(shade.adders) + 4
    assert c.tables == shade.tables and len(c.tables) == 1          # the power (cos^n) table
    assert c.dividers == [] and c.sqrts == 0


def test_sidecar_of_ernst_names_its_method():
    _, sidecar, command = build_unit("illumination", Config(method="ernst"))
    assert sidecar.method == "ernst" and "--method ernst" in command
    assert sidecar.error_bounds.lsb == max(fixed_peercy.predicted_error_bound_lsb(Config(), c)
                                             for c in ("diffuse", "specular", "color"))
