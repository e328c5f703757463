"""GlobeGeometry (rtl/globe.py) in the Amaranth simulator, bit for bit against the integer model
(sim/golden/globe.py) on random pixels and the corners, under every traffic pattern; the
model against float64 within its derived bound over whole discs and the rims of the widest
ones; the points whose outputs are known exactly; the square root alone, exhaustively; the
configuration's errors."""

import math

import numpy as np
import pytest
from amaranth.hdl import unsigned
from amaranth.lib import data

from bumprtl.gen.flow.emit import flat_verilog, lint
from bumprtl.rtl.config import BumpError, Config, ConfigError
from bumprtl.rtl.globe import (
    DATAPATH_BITS,
    GlobeConfig,
    GlobeGeometry,
    fit_signed,
    globe_out_layout,
    level_radicand_limits,
    level_thresholds,
    level_y_used,
    sqrt_stages,
    theta_table,
    v_table,
)
from bumprtl.rtl.pipe import ECP5, PipeUnit, unit_memory_records
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.golden import globe as model
from bumprtl.sim.golden.globe import (
    check_against_float,
    disc_pixels,
    error_bound_rad,
    globe_fixed,
    isqrt,
)
from bumprtl.sim.traffic import PATTERNS
from tests.rtl.test_no_clock_enable import datapath_offenders, netlist

SMALL = Config(angle_bits=10, frac_bits=9, tag_bits=8)
# Globes with four mip levels and F = 4 (coarse roots: at R = 88 some pixel's root is each
# threshold and one unit either side of it), on a 2:1 map (the x part alone decides) and a
# square map (the y part's table raises it)
LOD = {"radius": 88, "map_width": 512, "pipeline": SMALL, "coord_bits": 8, "frac_bits": 4,
       "mip_levels": 4}
LOD_WIDE = GlobeConfig(map_height=256, **LOD)
LOD_SQUARE = GlobeConfig(map_height=512, **LOD)


def rim_pixels(radius, limit=None):
    """Pixels at the rim in every quadrant: for each |x| <= R + 1, the outermost |y| inside
    and the next one out; and every pixel with r**2 in R**2 - 2 .. R**2 + 2 (on the rim,
    just inside, just outside), whichever exist."""
    rr, out = radius * radius, set()
    cols = range(radius + 2)
    if limit is not None and len(cols) > limit:
        cols = sorted({*np.linspace(0, radius + 1, limit).astype(int).tolist(), radius - 1, radius})
    for ax in cols:
        top = math.isqrt(max(rr - 1 - ax * ax, 0)) if ax * ax < rr else -1
        for ay in {top, top + 1}:
            if ay >= 0:
                out.update((sx * ax, sy * ay) for sx in (1, -1) for sy in (1, -1))
    for ax in range(radius + 3):
        for want in range(rr - 2, rr + 3):
            rest = want - ax * ax
            if rest >= 0 and math.isqrt(rest) ** 2 == rest:
                ay = math.isqrt(rest)
                out.update((sx * ax, sy * ay) for sx in (1, -1) for sy in (1, -1))
                out.update((sy * ay, sx * ax) for sx in (1, -1) for sy in (1, -1))
    return sorted(out)


def corner_pixels(gcfg):
    """The centre, the axis points (1, R - 1, R, R + 1 from the centre), the diagonals, the
    rim (:func:`rim_pixels`), the widest offsets the ports hold."""
    R, c = gcfg.radius, gcfg.coord_bits
    pts = {(0, 0)}
    for k in (1, R - 1, R, R + 1):
        pts.update({(k, 0), (-k, 0), (0, k), (0, -k)})
    k = max(1, int((R - 1) / math.sqrt(2)))
    pts.update({(k, k), (-k, k), (-k, -k), (k, -k)})
    lo, hi = -(1 << (c - 1)), (1 << (c - 1)) - 1
    pts.update({(lo, lo), (hi, hi), (lo, hi), (hi, 0), (0, lo)})
    pts.update(rim_pixels(R, limit=24))
    return sorted(pts)


def rtl_vs_model(gcfg, pixels, rotations, pattern, seed=0):
    """Every pixel at every rotation through GlobeGeometry, bit for bit against globe_fixed;
    returns (unit, cycles)."""
    x = np.array([p[0] for p in pixels for _ in rotations], np.int64)
    y = np.array([p[1] for p in pixels for _ in rotations], np.int64)
    rot = np.array([r for _ in pixels for r in rotations], np.int64)
    mask = (1 << gcfg.pipeline.tag_bits) - 1
    inputs = [{"x": int(a), "y": int(b), "rotation": int(r), "tag": (n * 37) & mask}
              for n, (a, b, r) in enumerate(zip(x, y, rot, strict=True))]
    dut = GlobeGeometry(gcfg)
    out, cycles = simulate_stream(dut, inputs, pattern, seed=seed, pipe_handshake=True)
    assert_bit_exact(out, globe_fixed(x, y, rot, gcfg), inputs)
    return dut, cycles


def test_corners_bit_exact_default():
    """The default globe (R = 224, 14-bit angles, 2048 x 1024 map): the corners at rotation
    0, the code just below a full turn (u wraps) and one between, under input gaps and
    backpressure."""
    g = GlobeConfig()
    top = g.pipeline.full_circle - 1
    rtl_vs_model(g, corner_pixels(g), [0, top, 5000], "both")


def test_corners_bit_exact_on_an_exact_rim():
    """R = 17 has pixels at r**2 = R**2 - 1 (12, 12), on the rim R**2 (8, 15) and at R**2 + 1
    (11, 13): inside, outside, outside; narrow angles and a small map."""
    g = GlobeConfig(radius=17, map_width=64, map_height=32, pipeline=SMALL, coord_bits=7,
                    frac_bits=12, guard_bits=3)
    rim = rim_pixels(17)
    assert {(12, 12), (8, 15), (11, 13)} <= set(rim)
    rtl_vs_model(g, corner_pixels(g), [0, SMALL.full_circle - 1], "backpressure")


@pytest.mark.parametrize("pattern", list(PATTERNS))
def test_random_pixels_bit_exact(pattern):
    """Random pixels over the disc and a ring outside it, random rotations."""
    g = GlobeConfig(radius=40, map_width=256, map_height=128, pipeline=SMALL, coord_bits=8)
    rng = np.random.default_rng(7 + len(pattern))
    pts = list(zip(rng.integers(-44, 45, 120).tolist(), rng.integers(-44, 45, 120).tolist(),
                   strict=True))
    x, y = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
    rot = rng.integers(0, SMALL.full_circle, len(pts))
    inputs = [{"x": int(a), "y": int(b), "rotation": int(r), "tag": n}
              for n, ((a, b), r) in enumerate(zip(pts, rot, strict=True))]
    dut = GlobeGeometry(g)
    out, _ = simulate_stream(dut, inputs, pattern, seed=3, pipe_handshake=True)
    assert_bit_exact(out, globe_fixed(x, y, rot, g), inputs)
    assert any(o["inside"] for o in out) and not all(o["inside"] for o in out)


def test_radius_one_and_widest_radius():
    """R = 1 (the centre alone is inside) and R = 2047 (the widest, its rim)."""
    rtl_vs_model(GlobeConfig(radius=1, map_width=4, map_height=2, pipeline=SMALL,
                             coord_bits=3, frac_bits=8, guard_bits=2),
                 [(a, b) for a in range(-2, 2) for b in range(-2, 2)], [0, 1023], "input_gaps")
    g = GlobeConfig(radius=2047, pipeline=Config(angle_bits=16, frac_bits=16, tag_bits=4))
    rtl_vs_model(g, [(0, 0), (2046, 0), (0, -2046), (-1, 2046), (1447, 1447), (1447, -1448),
                     *rim_pixels(2047, limit=6)], [65535], "no_stall")


def test_one_pixel_per_clock():
    g = GlobeConfig(radius=20, map_width=64, map_height=32, pipeline=SMALL, coord_bits=7,
                    frac_bits=8, guard_bits=2)
    dut, cycles = rtl_vs_model(g, [(a, a // 2) for a in range(-25, 25)], [9], "no_stall")
    assert dut.latency == g.latency
    assert cycles == 50 + dut.port_latency


def test_known_points():
    """Outputs known without either model, of the RTL and of the model: on the column x = 0
    (the centre, (0, +-5), the poles' neighbours) phi is exactly 3/4 turn (N = (0, -z, y)
    points at the viewer's side of the pole axis) and u the rotation's texel; on the row
    y = 0 theta is a quarter turn and v = H / 2; theta(y) + theta(-y) is half a turn;
    a pixel right of the column turns phi and u up, left of it down; outside every field
    but inside is 0."""
    g = GlobeConfig()
    R = g.radius
    pts = [(0, 0), (0, 5), (0, -5), (0, R - 1), (0, 1 - R), (5, 0), (-5, 0),
           (R, 0), (0, -R), (R, R)]
    rot = 12345
    inputs = [{"x": a, "y": b, "rotation": rot, "tag": n} for n, (a, b) in enumerate(pts)]
    rtl, _ = simulate_stream(GlobeGeometry(g), inputs, "no_stall")
    rtl = {k: np.array([o[k] for o in rtl]) for k in rtl[0]}
    for out in (rtl, globe_fixed([p[0] for p in pts], [p[1] for p in pts], rot, g)):
        _check_known(out, g, rot)


def _check_known(out, g, rot):
    A, W, H = g.angle_bits, g.map_width, g.map_height
    quarter, texel = 1 << (A - 2), rot * W >> A
    assert out["inside"].tolist() == [1] * 7 + [0] * 3
    phi, theta, u, v = (out[k].tolist() for k in ("n.phi", "n.theta", "u", "v"))
    assert phi[:5] == [3 * quarter] * 5 and u[:5] == [texel] * 5
    assert theta[0] == theta[5] == theta[6] == quarter and v[0] == v[5] == v[6] == H // 2
    assert theta[1] + theta[2] == theta[3] + theta[4] == 2 * quarter
    assert 0 < theta[3] < theta[1] < quarter                     # up the screen: toward the pole
    assert v[3] < v[1] < H // 2 < v[2] < v[4]                    # v grows down the screen
    assert phi[5] > 3 * quarter > phi[6] and u[5] > texel > u[6]
    for field in ("n.phi", "n.theta", "u", "v"):
        assert out[field][7:].tolist() == [0, 0, 0]


def test_latitude_tables_fall_and_are_symmetric():
    """v falls as y climbs (row 0 is the north pole), from below the equator's row to above
    it, and v(y) + v(-y) is H - 1 (or H where the latitude falls on a row's edge), as floor
    makes it; theta falls with y from near half a turn to near 0, theta(y) + theta(-y) is half
    a turn (acos(-t) = pi - acos(t)), and theta(0) is a quarter turn."""
    g = GlobeConfig()
    R, H, half = g.radius, g.map_height, g.pipeline.full_circle // 2
    vt, tt = v_table(g), theta_table(g)
    ys = list(range(-R + 1, R))
    vs = [vt[y % len(vt)] for y in ys]
    ts = [tt[y % len(tt)] for y in ys]
    assert vs == sorted(vs, reverse=True) and vs[0] > H // 2 > vs[-1]
    assert all(a + b in (H - 1, H) for a, b in zip(vs, reversed(vs), strict=True))
    assert ts == sorted(ts, reverse=True) and 0 < ts[-1] < ts[0] < half
    assert all(a + b == half for a, b in zip(ts, reversed(ts), strict=True))
    assert tt[0] == half // 2


def test_model_against_float_over_the_default_disc():
    """Every pixel of the default disc and a ring outside, at rotation 0 and just below a
    full turn: the fine angles within error_bound_rad, the codes and texels equal to
    float64's except off by one next to a rounding boundary; inside, theta and v equal.
    phi does not depend on the rotation (the sum's start is taken back off), so the disc is
    its whole input space: its measured maximum here is exhaustive, under one code even
    where the derived bound (loose near the poles, where the chain's vector is shortest) is
    not; u's bound is under one texel."""
    g = GlobeConfig()
    x, y = disc_pixels(g.radius)
    for rot in (0, g.pipeline.full_circle - 1):
        res = check_against_float(x, y, rot, g)
        assert res["violations"] == [], res
        assert res["pixels"] > 3 * g.radius ** 2
        assert res["lambda"]["bound_steps"] < 1
        for name in ("phi", "lambda"):
            assert res[name]["max_error_steps"] < 0.5 and res[name]["codes_max_diff"] <= 1
            assert res[name]["codes_differing"] < res["pixels"] // 50


def test_model_against_float_of_pixels_all_outside_the_disc():
    """Pixels none of which is inside (the corners of the screen): nothing to measure, so
    every figure is 0 and nothing is violated (an empty maximum is no error)."""
    g = GlobeConfig(radius=17)
    x = np.array([-40, 40, -40, 40, 18, 0])
    y = np.array([-40, -40, 40, 40, 0, 18])
    res = check_against_float(x, y, 0, g)
    assert res["pixels"] == 0 and res["violations"] == []
    for name in ("phi", "lambda"):
        assert res[name]["max_error_rad"] == 0 and res[name]["codes_max_diff"] == 0
        assert res[name]["codes_differing"] == 0


@pytest.mark.parametrize("radius,angle_bits,width,height,frac,guard", [
    (1, 8, 4, 2, 4, 1), (2, 8, 16, 8, 8, 2), (3, 16, 32768, 16384, 20, 8),
    (17, 10, 64, 32, 12, 3), (100, 12, 512, 256, 14, 4), (60, 12, 256, 256, 12, 4)])
def test_model_against_float_small_discs(radius, angle_bits, width, height, frac, guard):
    g = GlobeConfig(radius=radius, map_width=width, map_height=height,
                    pipeline=Config(angle_bits=angle_bits, frac_bits=max(angle_bits - 3, 4)),
                    frac_bits=frac, guard_bits=guard)
    x, y = disc_pixels(radius)
    for rot in (0, 1, (1 << angle_bits) - 1):
        assert check_against_float(x, y, rot, g)["violations"] == []


def test_model_against_float_at_the_widest_rim():
    """R = 2047, where the rim is steepest in pixels: the ring r**2 >= R**2 - 8R, the poles'
    columns and the centre's neighbours, at the default widths."""
    g = GlobeConfig(radius=2047)
    R = 2047
    xs, ys = [], []
    for col in range(-R - 2, R + 3):
        top = math.isqrt((R + 2) ** 2 - col * col) if col * col <= (R + 2) ** 2 else -1
        low = R * R - 8 * R - col * col
        bottom = math.isqrt(low - 1) + 1 if low > 0 else 0
        rows = np.arange(bottom, top + 1) if abs(col) > 3 else np.arange(0, top + 1)
        rows = np.concatenate([rows, -rows])
        xs.append(np.full(len(rows), col)), ys.append(rows)
    x, y = np.concatenate(xs), np.concatenate(ys)
    res = check_against_float(x, y, g.pipeline.full_circle - 1, g)
    assert res["violations"] == [], res
    assert res["pixels"] > 40000


def test_the_float_check_can_fail(monkeypatch):
    """A model that reads the wrong v word, or puts one texel off where float64 is clear of a
    boundary, is reported."""
    g = GlobeConfig(radius=30, map_width=256, map_height=128)
    x, y = disc_pixels(30)
    real = model.globe_fixed

    def off_u(*args, **kw):
        out = real(*args, **kw)
        out["u"] = np.where(out["inside"] == 1, (out["u"] + 1) % g.map_width, 0)
        return out

    monkeypatch.setattr(model, "globe_fixed", off_u)
    assert any(v.startswith("u:") for v in check_against_float(x, y, 0, g)["violations"])

    def off_v(*args, **kw):
        out = real(*args, **kw)
        out["v"] = np.where(out["inside"] == 1, np.maximum(out["v"] - 1, 0), 0)
        out["phi_fine"] = out["phi_fine"] + (1 << (g.angle_frac_bits - g.angle_bits))
        return out

    monkeypatch.setattr(model, "globe_fixed", off_v)
    bad = check_against_float(x, y, 0, g)["violations"]
    assert "v differs" in bad and any(v.startswith("phi: fine error") for v in bad)

    # the level one coarser or one finer where it can be, or one coarser only at the roots
    # one unit above a threshold (where the exact level is already the finer one)
    lx, ly = disc_pixels(LOD_WIDE.radius)
    monkeypatch.setattr(model, "globe_fixed", real)
    assert check_against_float(lx, ly, 0, LOD_WIDE)["violations"] == []
    above = {t + 1 for t in LOD_THRESHOLDS}
    roots = isqrt(np.maximum(LOD_WIDE.radius ** 2 - lx * lx - ly * ly, 0) << 8)
    for change in (lambda lv, _: np.minimum(lv + 1, 3), lambda lv, _: np.maximum(lv - 1, 0),
                   lambda lv, inside: np.where(inside & np.isin(roots, list(above)), lv + 1, lv)):
        def off_level(*args, change=change, **kw):
            out = real(*args, **kw)
            out["level"] = np.where(out["inside"] == 1, change(out["level"], out["inside"] == 1), 0)
            return out

        monkeypatch.setattr(model, "globe_fixed", off_level)
        bad = check_against_float(lx, ly, 0, LOD_WIDE)["violations"]
        assert any(v.startswith("level:") for v in bad), bad


def test_bound_shrinks_with_the_widths():
    """The derived bound is larger for narrower datapaths, fewer guard bits and a smaller
    radius (a shorter vector at the poles), and stays below one texel at the defaults."""
    g = GlobeConfig()
    b = error_bound_rad(g)
    assert b < 2 * math.pi / g.map_width
    assert error_bound_rad(GlobeConfig(frac_bits=g.fraction_bits - 2)) > b
    assert error_bound_rad(GlobeConfig(guard_bits=2)) > b
    assert error_bound_rad(GlobeConfig(radius=100, frac_bits=g.fraction_bits)) > b


class _Root(PipeUnit):
    """sqrt_stages on its own: floor(sqrt(s << 2F)) of an 8-bit s."""

    def __init__(self, frac_bits):
        self.frac_bits = frac_bits
        self.latency = 4 + frac_bits
        cfg = Config(tag_bits=8)
        super().__init__(cfg, data.StructLayout({"s": unsigned(8), "tag": unsigned(8)}),
                         data.StructLayout({"q": unsigned(4 + frac_bits), "tag": unsigned(8)}))

    def build(self, m, pipe):
        q = sqrt_stages(pipe, self.i.payload.s, 8, self.frac_bits, "root")
        m.d.comb += pipe.o.payload.q.eq(q)
        m.d.comb += pipe.o.payload.tag.eq(pipe.delay(self.i.payload.tag, self.latency, "tag"))


@pytest.mark.parametrize("frac_bits", [0, 3])
def test_square_root_exhaustive(frac_bits):
    """Every 8-bit radicand: the non-restoring root is floor(sqrt) exactly."""
    inputs = [{"s": s, "tag": s} for s in range(256)]
    out, _ = simulate_stream(_Root(frac_bits), inputs, "no_stall")
    assert [o["q"] for o in out] == [math.isqrt(s << (2 * frac_bits)) for s in range(256)]


def test_model_square_root_is_exact():
    rng = np.random.default_rng(5)
    n = np.concatenate([rng.integers(0, 1 << 62, 2000), [0, 1, 2, 3, (1 << 62) - 1],
                        np.arange(1, 3000) ** 2 - 1])
    assert isqrt(n).tolist() == [math.isqrt(int(v)) for v in n]


@pytest.mark.parametrize("changes,field", [
    ({"radius": 0}, "radius"), ({"radius": 2048}, "radius"), ({"radius": 3.0}, "radius"),
    ({"map_width": 3000, "map_height": 1500}, "map_width"),
    ({"map_width": 2, "map_height": 1}, "map_width"),
    ({"map_width": 2048, "map_height": 512}, "map_height"),
    ({"map_width": 1024, "map_height": 2048}, "map_height"),
    ({"radius": 300, "coord_bits": 9}, "coord_bits"), ({"coord_bits": 17}, "coord_bits"),
    ({"frac_bits": 3}, "frac_bits"), ({"frac_bits": 21}, "frac_bits"),
    ({"guard_bits": 0}, "guard_bits"), ({"guard_bits": 9}, "guard_bits"),
    ({"iterations": 1}, "iterations"), ({"iterations": 23}, "iterations"),
    ({"pipeline": "default"}, "pipeline"),
    ({"mip_levels": 0}, "mip_levels"), ({"mip_levels": 12}, "mip_levels"),
    ({"map_width": 64, "map_height": 32, "mip_levels": 7}, "mip_levels"),
    ({"mip_levels": 2.0}, "mip_levels")])
def test_config_errors_name_the_parameter(changes, field):
    with pytest.raises(ConfigError) as err:
        GlobeConfig(**changes)
    assert err.value.field == field and field in str(err.value)
    assert isinstance(err.value, BumpError)
    if field not in ("pipeline", "map_height"):
        assert "[" in str(err.value)           # the allowed range


def test_default_datapath_width_whatever_the_radius():
    """The default F keeps the roots' remainders and the CORDIC datapaths DATAPATH_BITS wide
    (the carry chains that bound the clock); an explicit F overrides it."""
    for radius in (1, 17, 224, 2047):
        g = GlobeConfig(radius=radius)
        assert g.datapath_bits == DATAPATH_BITS == g.root_bits + 2
    assert GlobeConfig(frac_bits=12).datapath_bits == 8 + 12 + 2


def test_config_accepts_the_edges():
    GlobeConfig(radius=2047)
    GlobeConfig(radius=1, coord_bits=2, map_width=4, map_height=2, frac_bits=4, guard_bits=1,
                iterations=2)
    GlobeConfig(map_width=32768, map_height=16384, frac_bits=20, guard_bits=8, iterations=23)
    GlobeConfig(map_width=32768, map_height=32768)
    GlobeConfig(map_width=4, map_height=4, radius=1, coord_bits=2)
    GlobeConfig(mip_levels=11)
    GlobeConfig(map_width=4, map_height=2, radius=1, coord_bits=2, mip_levels=2)
    GlobeConfig(map_width=32768, map_height=32768, mip_levels=16)


def test_elaborates_for_ecp5_and_records_its_rom():
    """The ECP5 form builds (DSP squares, the latitude ROMs in DP16KD); its memories are the
    v and theta tables."""
    g = GlobeConfig()
    dut = GlobeGeometry(g, target=ECP5())
    _, records = unit_memory_records(dut)
    mems = records.of(dut)
    assert (mems["v_rom"]["depth"], mems["v_rom"]["width"]) == (2 << g.int_bits, g.v_bits)
    assert (mems["theta_rom"]["depth"], mems["theta_rom"]["width"]) == (2 << g.int_bits, g.angle_bits)


@pytest.mark.regress
def test_no_register_or_read_has_an_enable(build_dir):
    """As tests/rtl/test_no_clock_enable.py checks every unit: only the credit edge's
    registers have enables."""
    module = netlist(GlobeGeometry(GlobeConfig(radius=40, coord_bits=8)), "globe", build_dir)
    assert datapath_offenders(module) == ([], [])


@pytest.mark.regress
def test_verilog_is_lint_clean(build_dir):
    """The emitted Verilog (flattened, as `bumprtl emit` writes a composed unit) passes
    Verilator's lint under the project's waivers."""
    path = build_dir / "globe_geometry.v"
    path.write_text(flat_verilog(GlobeGeometry(GlobeConfig()), "globe_geometry"))
    assert lint(path) == []


@pytest.mark.parametrize("value, width, expected", [
    ((0b1011, unsigned(4)), 3, 3),            # truncated to its low bits, read signed
    ((0b1111, unsigned(4)), 3, -1),
    ((-3, "signed6"), 4, -3),                 # a signed value narrowed
    ((0b101, unsigned(3)), 5, 5),             # unsigned: zero-extended
    ((-3, "signed3"), 6, -3)])                # signed: sign-extended
def test_fit_signed_extends_by_signedness_and_truncates_to_the_low_bits(value, width, expected):
    from amaranth.hdl import Const, Module, signed
    from amaranth.sim import Simulator

    v, shape = value
    shape = signed(int(shape[6:])) if isinstance(shape, str) else shape
    out = []

    async def bench(ctx):
        e = fit_signed(Const(v, shape), width)
        out.append((len(e), e.shape().signed, ctx.get(e)))

    sim = Simulator(Module())
    sim.add_testbench(bench)
    sim.run()
    assert out == [(width, True, expected)]


def exact_level(x, y, gcfg):
    """The level from the formula, in floats apart from either model: log2 max(W / (2 pi
    z), H / (pi s)) rounded to the nearest whole level (OpenGL's nearest mipmap),
    clamped to [0, L - 1], 0 outside."""
    R, W, H, L = gcfg.radius, gcfg.map_width, gcfg.map_height, gcfg.mip_levels
    if x * x + y * y >= R * R:
        return 0
    z, s = math.sqrt(R * R - x * x - y * y), math.sqrt(R * R - y * y)
    rho = max(W / (2 * math.pi * z), H / (math.pi * s))
    return min(max(math.floor(math.log2(rho) + 0.5), 0), L - 1)


# The thresholds of LOD_WIDE and LOD_SQUARE, floor(W 2**F / (2 pi 2**(k - 1/2))) for W =
# 512, F = 4: 8192 / (2 pi sqrt 2) = 921.9.., 460.9.., 230.4..
LOD_THRESHOLDS = [921, 460, 230]


def threshold_pixels(gcfg):
    """For each threshold t_k of LOD_THRESHOLDS and each root t_k - 1, t_k, t_k + 1: the
    first pixel (x, y >= 0, by rows from the centre) whose root floor(sqrt(R**2 - r**2) 2**F)
    (math.isqrt) is it; {(k, offset): (x, y)}."""
    R, F = gcfg.radius, gcfg.fraction_bits
    want = {t + o: (k, o) for k, t in enumerate(LOD_THRESHOLDS, 1) for o in (-1, 0, 1)}
    found = {}
    for y in range(R):
        for x in range(R):
            if x * x + y * y < R * R:
                key = want.get(math.isqrt((R * R - x * x - y * y) << (2 * F)))
                if key is not None and key not in found:
                    found[key] = (x, y)
    return found


def test_level_thresholds_from_the_formula():
    """t_k = floor(W 2**F / (2 pi 2**(k - 1/2))): LOD_THRESHOLDS; the default F = 10 on a
    2048-wide map 2**21 / (2 pi sqrt 2) = 236012.1.., 118006.0.."""
    assert level_thresholds(LOD_WIDE) == level_thresholds(LOD_SQUARE) == LOD_THRESHOLDS
    assert level_thresholds(GlobeConfig(mip_levels=3)) == [236012, 118006]
    assert level_thresholds(GlobeConfig()) == []


def test_level_radicand_limits_are_the_thresholds_on_the_radicand():
    """The RTL compares the radicand d with c_k where the model compares the root with t_k:
    c_k is the largest d whose root floor(sqrt(d 2**(2F))) (math.isqrt) is at most t_k. A
    4096-wide map at F = 4 has t_1 = floor(2**16 / (2 pi sqrt 2)) = 7375, t_1 + 1 a multiple
    of 2**F: there (t_1 + 1)**2 is a whole d 2**(2F), whose root is t_1 + 1, and c_1 =
    (7376**2 - 1) >> 8 = 212520."""
    edge = GlobeConfig(map_width=4096, map_height=2048, frac_bits=4, mip_levels=2)
    assert level_thresholds(edge) == [7375] and level_radicand_limits(edge) == [212520]
    for g in (LOD_WIDE, edge, GlobeConfig(mip_levels=11), GlobeConfig(radius=2047, mip_levels=11),
              GlobeConfig(radius=3, map_width=32768, map_height=16384, frac_bits=20,
                          mip_levels=15)):
        f = g.fraction_bits
        for t, c in zip(level_thresholds(g), level_radicand_limits(g), strict=True):
            assert math.isqrt(c << 2 * f) <= t < math.isqrt((c + 1) << 2 * f)


@pytest.mark.parametrize("gcfg", [LOD_WIDE, LOD_SQUARE], ids=["wide", "square"])
def test_level_bit_exact(gcfg):
    """The level of the RTL bit for bit against the model's: the corners, the pixels on each
    threshold and one unit either side of it, random pixels over the disc, under input gaps
    and backpressure; on the 2:1 map (no y part) and the square one (its table in the v
    ROM's word)."""
    assert level_y_used(gcfg) == (gcfg.map_height == gcfg.map_width)
    rng = np.random.default_rng(11)
    pts = [*corner_pixels(gcfg), *threshold_pixels(gcfg).values(),
           *zip(rng.integers(-92, 93, 100).tolist(), rng.integers(-92, 93, 100).tolist(),
                strict=True)]
    rtl_vs_model(gcfg, pts, [0, 700], "both")


def _level_points(gcfg):
    """(pixel, level) known from the formula."""
    R = gcfg.radius
    pts = [((0, 0), 1 if gcfg.map_height == gcfg.map_width else 0),   # rho 0.93 (W = 2H), 1.85
           ((75, 46), 3), ((-46, -75), 3),      # r**2 = R**2 - 3: rho 47, clamped to L - 1
           ((R, 0), 0), ((0, -R), 0), ((R, R), 0), ((-95, 3), 0)]          # outside: 0
    for (k, o), (x, y) in threshold_pixels(gcfg).items():
        # the root at t_k reaches level k (z may be up to a unit above the real threshold),
        # a unit above it level k - 1, a unit below level k (t_(k+1) is far lower): the
        # x part alone; the y part as the formula gives it
        x_part = k - (o == 1)
        y_part = exact_level(0, y, gcfg) if gcfg.map_height == gcfg.map_width else 0
        pts.append(((x, y), max(x_part, y_part)))
    return pts


@pytest.mark.parametrize("gcfg", [LOD_WIDE, LOD_SQUARE], ids=["wide", "square"])
def test_level_known_points(gcfg):
    """Levels known from the formula, of the RTL and of the model: the centre (z = R, rho =
    W / (2 pi R) = 0.93 on the 2:1 map, H / (pi R) = 1.85 on the square one: levels 0 and
    1, log2 rounded), pixels next to the rim (rho 47, clamped to L - 1), the pixels whose root is each threshold or one
    unit off it, 0 outside."""
    known = _level_points(gcfg)
    # every threshold's own root and the root a unit below it are reached at R = 88 (the
    # unit above only where some x**2 + y**2 gives it: 461 and 231 are not)
    assert {(k, o) for k in (1, 2, 3) for o in (-1, 0)} <= set(threshold_pixels(gcfg))
    assert len(known) >= 7 + 6
    pts = [p for p, _ in known]
    inputs = [{"x": a, "y": b, "rotation": 3, "tag": n} for n, (a, b) in enumerate(pts)]
    rtl, _ = simulate_stream(GlobeGeometry(gcfg), inputs, "no_stall")
    fixed = globe_fixed([p[0] for p in pts], [p[1] for p in pts], 3, gcfg)
    want = [lv for _, lv in known]
    assert [o["level"] for o in rtl] == want
    assert fixed["level"].tolist() == want
    # the formula agrees away from the thresholds
    assert [exact_level(*p, gcfg) for p in pts[:7]] == want[:7]


def test_level_below_one_texel_is_zero():
    """rho < 1 (a 512-wide map on R = 224: W / (2 pi R) = 0.36 at the centre) gives 0, not a
    negative level; towards the rim rho grows to 3.9 at (223, 0) (z = sqrt 447) and 4.4 at
    (10, -223) (z = sqrt 347): log2 1.96 and 2.13, rounded to the top level, 2."""
    g = GlobeConfig(map_width=512, map_height=256, mip_levels=3)
    pts = [(0, 0), (100, 0), (223, 0), (223, 10), (10, -223)]
    out = globe_fixed([p[0] for p in pts], [p[1] for p in pts], 0, g)
    assert out["level"].tolist() == [exact_level(*p, g) for p in pts] == [0, 0, 2, 2, 2]


@pytest.mark.parametrize("gcfg", [
    LOD_WIDE, LOD_SQUARE, GlobeConfig(mip_levels=11),
    GlobeConfig(map_width=1024, map_height=1024, mip_levels=11),
    GlobeConfig(radius=60, map_width=256, map_height=256, mip_levels=9, frac_bits=5),
    GlobeConfig(radius=26, map_width=128, map_height=64, mip_levels=4, frac_bits=4)],
    ids=["wide", "square", "default-11", "square-11", "square-F5", "coarser"])
def test_level_against_float(gcfg):
    """Over the disc and a ring outside: the level equals float64's (max of du/dx and dv/dy
    from float64 z and s) but one coarser where the root is on that level's threshold; on the
    2:1 maps the model has no y part and float64 does, so the y part never raising a 2:1
    map's level is checked too. At R = 26 (F = 4) some pixels have a root on a
    threshold above the real one: their level is the coarser one (W = 128 there)."""
    x, y = disc_pixels(gcfg.radius)
    res = check_against_float(x, y, 0, gcfg)
    assert res["violations"] == [], res
    assert (res["level"]["differing"] > 0) == (gcfg.radius == 26)
    per = res["level"]["per_level"]
    assert per[0] + per[1] > 0 and per[-1] + per[-2] > 0 or gcfg.mip_levels > 8
    if gcfg.frac_bits == 4:
        assert res["level"]["pixels_at_threshold"] > 0
        # every level on the 2:1 map; the square map's y part lifts its centre to 1
        assert all(per) if gcfg.map_height < gcfg.map_width else per[0] == 0 < per[1]


def test_level_layout_only_with_mip_levels():
    """No level field at one level (the unit unchanged); level_bits wide from two."""
    assert "level" not in dict(globe_out_layout(GlobeConfig())).keys()
    for levels, bits in ((2, 1), (3, 2), (4, 2), (5, 3), (11, 4)):
        g = GlobeConfig(mip_levels=levels)
        assert g.level_bits == bits
        assert dict(globe_out_layout(g))["level"].shape == unsigned(bits)


def test_level_y_part_packed_in_the_v_rom():
    """The square map's y part rides above v in the v ROM's word; a 2:1 map's ROM is v's."""
    for g, width in ((LOD_SQUARE, 9 + 2), (LOD_WIDE, 8)):
        _, records = unit_memory_records(dut := GlobeGeometry(g))
        assert records.of(dut)["v_rom"]["width"] == width
