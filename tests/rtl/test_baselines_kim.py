"""The kim baseline datapaths (rtl/baselines/kim.py): bit for bit against
sim/golden/fixed/kim.py in the Amaranth simulator (random, edge, stress and tiny-width vectors,
with and without stalls), the reciprocal ROM against float64, emission (lint-clean,
deterministic, ``bumprtl emit rotation --method kim``) and the Yosys counts implied by the
structure in the module docstring (Lee Table 1's Kim column)."""

import subprocess
import sys

import numpy as np
import pytest

from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.resources import count_component, count_verilog, multiplier_pairs
from bumprtl.gen.flow.units import build_unit, emit_unit
from bumprtl.rtl import tables
from bumprtl.rtl.baselines.kim import KimRotation
from bumprtl.rtl.config import Config
from bumprtl.rtl.pipe import EDGE_LATENCY
from bumprtl.rtl.shade import BackEnd
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.amaranth_stream import check_datapath
from bumprtl.sim.golden.fixed.kim import predicted_error_bound_lsb
from bumprtl.sim.golden.stress import stress_codes
from bumprtl.sim.golden.vectors import TINY, concat_codes, edge_codes, random_codes
from bumprtl.sim.traffic import PATTERNS

NARROW = Config(method="kim", angle_bits=8, frac_bits=9)


# --- bit-exact against the golden model -----------------------------------------------------

# no stall in make test, the stalling patterns in make regress: the stall rule is the shared
# credit edge's, which every unit's own tests run under each pattern, and make test runs
# Kim's units under backpressure and under input gaps below (the widest and the narrow
# configurations)
@pytest.mark.parametrize("pattern", [p if p == "no_stall" else
                                     pytest.param(p, marks=pytest.mark.regress) for p in PATTERNS])
def test_bit_exact_random_and_edges(pattern):
    """300 random valid pixels and the edge cases (poles, azimuth wrap, L = N, grazing,
    below the horizon) without stalls, one pixel per clock (N + latency cycles); 300 random
    pixels under each stalling pattern. (The random volume on Kim's units: make regress's
    cocotb runs, tests/sim/tb/test_tb_datapath.py.)"""
    cfg = Config(method="kim")
    codes = random_codes(300, cfg, seed=len(pattern))
    if pattern == "no_stall":
        codes = concat_codes(edge_codes(cfg), codes)
    rot, ill = check_datapath(cfg, codes, pattern)
    total = len(codes["n.phi"])
    if pattern == "no_stall":
        assert rot == ill == total
    else:
        assert rot > total and ill > total


def test_bit_exact_stress_cases_at_the_widest_widths():
    """angle_bits 16, frac_bits 24: the widest products (M A: 26 x 26 bits, three summed)
    and the 25 x 25 bit divide must stay inside int64 in the golden model."""
    cfg = Config(method="kim", angle_bits=16, frac_bits=24, spec_index_bits=16)
    check_datapath(cfg, stress_codes(240, cfg, seed=3), "backpressure")


def test_bit_exact_narrow_without_specular():
    """8-bit angles, B = 9, no H path (its ROMs and multipliers are not built)."""
    cfg = NARROW.replace(specular=False)
    check_datapath(cfg, random_codes(300, cfg, seed=4), "input_gaps")


def test_bit_exact_tiny_config():
    """k = 2 (4-bit angles, B = 4, so the asin address is shifted left): 2048 vectors; L walks
    all 16^2 (th_N, th_L) for 8 azimuth pairs (ph_N, ph_L), H and N' move too."""
    cfg = TINY.replace(method="kim")
    idx = np.arange(2048, dtype=np.int64)
    a, b, c = idx & 15, (idx >> 4) & 15, idx >> 8
    codes = {"n.phi": (3 * c) & 15, "n.theta": a, "l.theta": b, "l.phi": (5 * c + a) & 15,
             "h.theta": (a + b) & 15, "h.phi": (7 * b + c) & 15, "b.phi": (a + c) & 15, "b.theta": b}
    check_datapath(cfg, codes, "no_stall")


# --- tables and structure --------------------------------------------------------------------

@pytest.mark.parametrize("cfg", [Config(method="kim"), NARROW,
                                 Config(method="kim", angle_bits=16, frac_bits=24)])
def test_reciprocal_table_against_float(cfg):
    """Every divisor P in [1, 2) whose mantissa selects entry i gets 1/P within a relative
    2**-(R+1) (the middle of the interval) plus the entry's rounding."""
    r, one = tables.kim_reciprocal_bits(cfg), cfg.one
    table = tables.kim_reciprocal_table(cfg)
    assert len(table) == 1 << r and table.max() < 1 << (cfg.frac_bits + 1)
    i = np.arange(1 << r)
    for edge in (0.0, 1.0):                         # both ends of each interval
        p = 1.0 + (i + edge) / (1 << r)
        rel = np.abs(table / one * p - 1.0)
        assert rel.max() <= 2.0 ** -(r + 1) + 0.5 / one * 2 + 1e-12


def _roms(unit, cfg):
    return build_unit(unit, cfg)[1].roms


def test_roms():
    """Setup: N's sin & cos ROM, and per vector sin & cos, reciprocal, atan, asin ROMs;
    illumination: N' and per-vector sin & cos ROMs plus the specular table. Without specular
    the H path is not built."""
    cfg = Config(method="kim")
    per_vector = ("sincos", "recip", "atan", "asin")
    assert sorted(_roms("rotation", cfg)) == sorted(
        ["n_sincos_rom"] + [f"{v}_{kind}_rom" for v in "lh" for kind in per_vector])
    assert sorted(_roms("rotation", cfg.replace(specular=False))) == sorted(
        ["n_sincos_rom"] + [f"l_{kind}_rom" for kind in per_vector])
    ill = _roms("illumination", cfg)
    assert sorted(n for n in ill if not n.startswith("specular")) == sorted(
        ["b_sincos_rom", "l_sincos_rom", "h_sincos_rom"])
    assert len(ill) == 4                              # + the back end's specular table


# --- emission ------------------------------------------------------------------------------

@pytest.mark.parametrize("unit", ["illumination", pytest.param("rotation", marks=pytest.mark.regress)])
def test_emission_lint_clean_and_deterministic(unit, build_dir):
    v1, j1 = emit_unit(unit, Config(method="kim"), build_dir / "a")
    v2, j2 = emit_unit(unit, Config(method="kim"), build_dir / "b")
    assert v1.read_bytes() == v2.read_bytes() and j1.read_bytes() == j2.read_bytes()
    assert "--method kim" in v1.read_text().splitlines()[0]
    assert lint(v1) == []


# make regress: make test runs the command line's emission of a baseline with Peercy's
# (tests/rtl/test_baselines_cartesian.py) and Kim's emission through the API above
@pytest.mark.regress
def test_cli_emit_rotation_method_kim(tmp_path, run_cli):
    """The command line writes what emit_unit writes, byte for byte (deterministic across
    processes), and it is lint-clean. At 10-bit angles, B = 11: the default widths' ROMs
    would double the time (make regress lints the default's rotation, the test above)."""
    cfg = Config(method="kim", angle_bits=10, frac_bits=11)
    r = subprocess.run([sys.executable, "-m", "bumprtl.gen.cli.main", "emit", "rotation", "--method",
                        "kim", "--angle-bits", "10", "--frac-bits", "11", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    v, j = emit_unit("rotation", cfg, tmp_path / "api", module="bumprtl_rotation")
    assert v.read_bytes() == (tmp_path / "bumprtl_rotation.v").read_bytes()
    assert j.read_bytes() == (tmp_path / "bumprtl_rotation.json").read_bytes()
    assert lint(v) == []
    assert (tmp_path / "bumprtl_rotation.v").read_text().startswith(
        f"// Generated by: bumprtl emit rotation --method kim --angle-bits {cfg.angle_bits} "
        f"--frac-bits {cfg.frac_bits}")
    meta = load_sidecar(tmp_path / "bumprtl_rotation.json")
    assert meta.method == "kim" and meta.latency == KimRotation.latency + EDGE_LATENCY
    assert meta.error_bounds.lsb == max(predicted_error_bound_lsb(cfg, c)
                                          for c in ("diffuse", "specular", "color"))
    bad = run_cli(["emit", "rotation", "--method", "kim", "--frac-bits", "40", "--out", tmp_path])
    assert bad.returncode == 2 and "frac_bits" in bad.stderr and "Traceback" not in bad.stderr


# --- Yosys counts against the structure (module docstring) -----------------------------------

def _table(t):
    """(ROM, depth, width, reads): a registered ROM's Memory is named ``<ROM>.mem``."""
    return (t["name"].removesuffix(".mem"), t["depth"], t["width"], t["read_ports"])


def _width(table):
    """Bits that vary from word to word: Yosys drops ROM bits that are constant (0 or 1) in
    every word (e.g. the leading one of every reciprocal in (1/2, 1])."""
    t = np.asarray(table, dtype=np.int64)
    return sum(len(np.unique((t >> n) & 1)) > 1 for n in range(int(t.max()).bit_length()))


def test_rotation_counts_match_the_structure(build_dir):
    """Per pixel 4 products for M; per vector 2 (polar -> Cartesian) + 8 (M A) of Q1.B
    values, the divide qn x 1/pn (unsigned B+1 bits each), rho = p cos a0 + q sin a0 (p, q
    unsigned B+2 bits; sin a0 >= 0 for a0 <= 45 deg, so its sign logic folds away);
    6 signal adders per vector (2 + 1 + 2 in M A, 1 in rho); the tables of the docstring."""
    cfg = NARROW
    b, vs = cfg.frac_bits, ("h", "l")
    v_path, _ = emit_unit("rotation", cfg, build_dir)
    c = count_verilog(v_path, "rotation", build_dir / "yosys")
    q = b + 2                                                   # a signed Q1.B value
    expected = [(q, q)] * (4 + len(vs) * 10)
    expected += [(b + 1, b + 1), (q + 1, q), (q, b + 1)] * len(vs)
    assert multiplier_pairs(c.multipliers) == multiplier_pairs(f"{x}x{y}" for x, y in expected)
    assert len(c.adders) == 6 * len(vs)
    assert c.dividers == [] and c.sqrts == 0
    roms = {"sincos": tables.quarter_sine(cfg), "recip": tables.kim_reciprocal_table(cfg),
            "atan": tables.lee_atan_table(cfg), "asin": tables.lee_asin_table(cfg)}
    assert len(roms["recip"]) == 1 << tables.kim_reciprocal_bits(cfg)
    assert len(roms["atan"]) == tables.lee_atan_depth(cfg)
    assert len(roms["asin"]) == (1 << tables.lee_asin_index_bits(cfg)) + 1
    reads = {"sincos": 6, "recip": 1, "atan": 1, "asin": 1}
    want = [("n_sincos_rom", len(roms["sincos"]), _width(roms["sincos"]), 4)]
    want += [(f"{v}_{kind}_rom", len(t), _width(t), reads[kind]) for v in vs for kind, t in roms.items()]
    assert sorted(map(_table, c.tables)) == sorted(want)



def test_illumination_counts_are_the_back_end_plus_eqs_3_and_4(build_dir):
    """Eqs (3)/(4) per vector: cos cos, sin sin, (sin sin) cos(dph): 3 products of Q1.B
    values; 2 adders (ph_A' - ph_N', the sum); one sin & cos ROM with 3 reads, plus N''s with
    2. Everything else is the shared back end, counted on its own."""
    cfg = NARROW
    b = cfg.frac_bits
    v_path, _ = emit_unit("illumination", cfg, build_dir)
    c = count_verilog(v_path, "illumination", build_dir / "yosys")
    shade = count_component(BackEnd(cfg), "shade_only", build_dir / "shade")
    q = b + 2
    assert multiplier_pairs(c.multipliers) == multiplier_pairs(
        shade.multipliers + [f"{q}x{q}"] * 6)
    assert len(c.adders) == len(shade.adders) + 4
    sincos = len(tables.quarter_sine(cfg))
    want = sorted(map(_table, shade.tables)) + [("b_sincos_rom", sincos, b + 1, 2),
                                                ("h_sincos_rom", sincos, b + 1, 3),
                                                ("l_sincos_rom", sincos, b + 1, 3)]
    assert sorted(map(_table, c.tables)) == sorted(want)
