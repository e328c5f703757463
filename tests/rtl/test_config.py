import math

import pytest

from bumprtl.rtl.config import Config, ConfigError


@pytest.mark.parametrize("field, value, words", [
    ("angle_bits", 3, ["angle_bits", "[4, 16]"]),
    ("angle_bits", 17, ["angle_bits", "[4, 16]"]),
    ("frac_bits", 10, ["frac_bits", "[11, 24]"]),     # default k = 12 needs B >= 11
    ("frac_bits", 33, ["frac_bits", "24"]),
    ("tag_bits", 40, ["tag_bits", "[0, 32]"]),
    ("spec_exponent", 0, ["spec_exponent", "[1, 1024]"]),
    ("method", "cordic", ["method", "exact", "lee"]),
    ("kd", 1.5, ["kd", "[0, 1]"]),
    ("palette_size", 8, ["palette_size", "[16, 16384]"]),
    ("angle_bits", 12.0, ["angle_bits", "integer"]),
])
def test_bad_field_is_named_with_its_range(field, value, words):
    with pytest.raises(ConfigError) as e:
        Config(**{field: value})
    for w in words:
        assert w in str(e.value)


def test_derived_widths():
    cfg = Config(angle_bits=12, frac_bits=13)
    assert (cfg.k, cfg.sincos_depth, cfg.sincos_width, cfg.one) == (10, 1025, 15, 8192)
    cfg = Config()                                # the default: 14-bit angles, B = 15
    assert (cfg.k, cfg.sincos_depth, cfg.sincos_width, cfg.one) == (12, 4097, 17, 32768)


def test_replace_validates_and_rejects_unknown_fields():
    with pytest.raises(ConfigError, match="frac_bits"):
        Config().replace(frac_bits=2)
    with pytest.raises(ConfigError, match="unknown Config field"):
        Config().replace(bits=3)


# Config's documented ranges (its docstring), as (field, lo, hi, other fields that set the
# range): each is refused one step outside on both sides, naming the field (BumpError.field,
# not the wording), and accepted at both ends. frac_bits's lower end follows k = angle_bits - 2.
RANGES = [
    ("angle_bits", 4, 16, {}),
    ("frac_bits", 11, 24, {}),                                  # default k = 12: B >= k - 1
    ("frac_bits", 9, 24, {"angle_bits": 12}),                   # k = 10: B >= 9
    ("frac_bits", 4, 24, {"angle_bits": 4}),                    # k = 2: B >= 4
    ("frac_bits", 13, 24, {"angle_bits": 16}),                  # k = 14: B >= 13
    ("tag_bits", 0, 32, {}),
    ("out_bits", 8, 8, {}),
    ("spec_exponent", 1, 1024, {}),
    ("spec_index_bits", 4, 16, {}),
    ("lights", 1, 8, {}),
    ("palette_size", 16, 16384, {}),
    ("color_bits", 8, 8, {}),
    ("ka", 0.0, 1.0, {}),
    ("kd", 0.0, 1.0, {}),
    ("ks", 0.0, 1.0, {}),
]


@pytest.mark.parametrize("field, lo, hi, base", RANGES,
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in RANGES])
def test_every_range_is_checked_on_both_sides(field, lo, hi, base):
    for value in (lo, hi):
        assert getattr(Config(**base, **{field: value}), field) == value
    outside = [lo - 1, hi + 1]
    if isinstance(lo, float):                                   # the nearest floats outside too
        outside += [math.nextafter(lo, -math.inf), math.nextafter(hi, math.inf)]
    for value in outside:
        with pytest.raises(ConfigError) as e:
            Config(**base, **{field: value})
        assert e.value.field == field, (value, str(e.value))


@pytest.mark.parametrize("field, value", [("method", "cordic"), ("specular", 1),
                                          ("palette_blend", "yes"), ("angle_bits", 12.0),
                                          ("lights", True)])
def test_bad_type_or_choice_names_the_field(field, value):
    with pytest.raises(ConfigError) as e:
        Config(**{field: value})
    assert e.value.field == field


@pytest.mark.parametrize("angle_bits", [8, 12, 14, 16])
def test_the_frac_bits_floor_the_message_explains_is_the_range_it_gives(angle_bits):
    """The explanation's B >= k - 1 (k = angle_bits - 2) is the range's own lower end, and
    the refused value and both ends are named."""
    k = angle_bits - 2
    with pytest.raises(ConfigError) as e:
        Config(angle_bits=angle_bits, frac_bits=3)
    msg = str(e.value)
    lo = max(4, k - 1)
    assert msg.startswith(f"frac_bits = 3 is out of range: allowed [{lo}, 24] (")
    assert f"B >= k - 1 = {k - 1} " in msg


def test_a_range_without_an_explanation_ends_at_the_range():
    for kw, text in (({"lights": 9}, "lights = 9 is out of range: allowed [1, 8]"),
                     ({"spec_index_bits": 3}, "spec_index_bits = 3 is out of range: allowed [4, 16]")):
        with pytest.raises(ConfigError) as e:
            Config(**kw)
        assert str(e.value) == text
    with pytest.raises(ConfigError) as e:
        Config(angle_bits=3)
    assert str(e.value).endswith("allowed [4, 16] (k = angle_bits - 2 must be >= 2)")


@pytest.mark.parametrize("field, value", [("ka", True), ("kd", False), ("ks", "0.5"),
                                          ("palette_blend", 1)])
def test_a_flag_of_the_wrong_type_is_refused_naming_field_and_value(field, value):
    """A bool is no coefficient (True == 1 would pass the range), a string no number."""
    with pytest.raises(ConfigError) as e:
        Config(**{field: value})
    assert e.value.field == field
    assert str(e.value).startswith(field) and repr(value) in str(e.value)


def test_to_dict_holds_every_field_by_name():
    import dataclasses
    cfg = Config(angle_bits=12, ks=0.25, specular=False)
    d = cfg.to_dict()
    assert d == {f.name: getattr(cfg, f.name) for f in dataclasses.fields(Config)}
    assert Config(**d) == cfg


def test_out_bits_refusal_says_why():
    """out_bits has one allowed value; its refusal says why (the outputs are 8-bit
    intensities), not only the one-value range."""
    with pytest.raises(ConfigError, match=r"out_bits = 9 is out of range: allowed \[8, 8\] "
                                          r"\(outputs are 8-bit intensities\)"):
        Config(out_bits=9)


def test_replace_names_the_unknown_field():
    """Config.replace refuses a field Config does not have, naming it (message and field)."""
    with pytest.raises(ConfigError, match=r"unknown Config field\(s\): nosuch") as e:
        Config().replace(nosuch=1)
    assert e.value.field == "nosuch"


# ---- every documented formula, range end and refusal, from Config's docstring and the
# ---- BumpError rule (one line naming the parameter, the value and its allowed range)

from bumprtl.rtl.config import FRAC_BITS_MAX, frac_bits_floor  # noqa: E402
from bumprtl.rtl.methods import METHODS  # noqa: E402

INT_FIELDS = [r for r in RANGES if isinstance(r[1], int)]


@pytest.mark.parametrize("angle_bits", range(4, 17))
def test_derived_properties_follow_the_number_formats(angle_bits):
    """k = angle_bits - 2, a full circle of 2**angle_bits steps, a quarter-wave ROM of
    2**k + 1 entries, sin/cos B + 2 bits wide and 1.0 == 2**B (module docstring)."""
    for frac_bits in (frac_bits_floor(angle_bits), FRAC_BITS_MAX):
        cfg = Config(angle_bits=angle_bits, frac_bits=frac_bits)
        k = angle_bits - 2
        assert cfg.k == k
        assert cfg.full_circle == 2 ** angle_bits
        assert cfg.sincos_depth == 2 ** k + 1
        assert cfg.sincos_width == frac_bits + 2
        assert cfg.one == 2 ** frac_bits


@pytest.mark.parametrize("angle_bits", range(4, 17))
def test_frac_bits_floor_is_k_minus_1_and_at_least_4(angle_bits):
    """frac_bits_floor: B >= k - 1 (and 4); Config accepts the floor and 24 and refuses one
    step past either, naming frac_bits and the range."""
    floor = max(4, (angle_bits - 2) - 1)
    assert frac_bits_floor(angle_bits) == floor
    for ok in (floor, FRAC_BITS_MAX):
        assert Config(angle_bits=angle_bits, frac_bits=ok).frac_bits == ok
    for bad in (floor - 1, FRAC_BITS_MAX + 1):
        with pytest.raises(ConfigError) as e:
            Config(angle_bits=angle_bits, frac_bits=bad)
        assert e.value.field == "frac_bits"
        assert f"[{floor}, {FRAC_BITS_MAX}]" in str(e.value)


def test_documented_defaults():
    """Config's docstring and docs/architecture.md: 14-bit angles, B = 15, n = 16, a
    10-bit specular index, the exact method, one light, 8-bit outputs and colours, the H
    path built and no palette blend (``--palette-blend`` turns it on, docs/palette.md)."""
    cfg = Config()
    assert (cfg.angle_bits, cfg.frac_bits, cfg.spec_exponent, cfg.spec_index_bits) == (14, 15, 16, 10)
    assert (cfg.method, cfg.lights, cfg.out_bits, cfg.color_bits) == ("exact", 1, 8, 8)
    assert cfg.specular is True and cfg.palette_blend is False
    for name in ("ka", "kd", "ks"):
        assert 0.0 <= getattr(cfg, name) <= 1.0


@pytest.mark.parametrize("field, lo, hi, base", INT_FIELDS,
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in INT_FIELDS])
def test_an_integer_out_of_range_is_one_line_naming_field_value_and_range(field, lo, hi, base):
    """BumpError's rule: one line that names the parameter, the refused value and its
    allowed range, and ``field`` is the parameter."""
    for value in (lo - 1, hi + 1):
        with pytest.raises(ConfigError) as e:
            Config(**base, **{field: value})
        msg = str(e.value)
        assert e.value.field == field and "\n" not in msg
        assert msg.startswith(f"{field} = {value} ") and f"[{lo}, {hi}]" in msg, msg


@pytest.mark.parametrize("field, lo, hi, base", INT_FIELDS,
                         ids=[f"{r[0]}-{r[1]}-{r[2]}" for r in INT_FIELDS])
def test_an_integer_field_refuses_a_bool_float_or_string_naming_the_range(field, lo, hi, base):
    """An integer field takes an int only (True == 1 and 8.0 == 8 are no widths); the
    refusal names the field, the value and the range."""
    for value in (True, float(lo), str(lo)):
        with pytest.raises(ConfigError) as e:
            Config(**base, **{field: value})
        msg = str(e.value)
        assert e.value.field == field
        assert msg.startswith(field) and repr(value) in msg and f"[{lo}, {hi}]" in msg, msg


@pytest.mark.parametrize("field", ["ka", "kd", "ks"])
def test_a_coefficient_is_any_number_in_0_1_and_a_refusal_names_it(field):
    """ka, kd, ks: each a number in [0, 1] (ints 0 and 1 too); outside, the message names the
    field, the range and the value."""
    for value in (0, 1, 0.0, 0.5, 1.0):
        assert getattr(Config(**{field: value}), field) == value
    for value in (-0.25, 1.25, None):
        with pytest.raises(ConfigError) as e:
            Config(**{field: value})
        msg = str(e.value)
        assert e.value.field == field
        assert msg.startswith(field) and "[0, 1]" in msg and repr(value) in msg, msg


def test_an_unknown_method_lists_every_method_of_the_registry():
    """method must be a name of rtl/methods.py's METHODS; the refusal names the field, the
    value and the allowed names, comma-separated in registry order; each name is accepted."""
    for name in METHODS:
        assert Config(method=name).method == name
    with pytest.raises(ConfigError) as e:
        Config(method="cordic")
    msg = str(e.value)
    assert e.value.field == "method" and msg.startswith("method")
    assert ", ".join(METHODS) in msg and "'cordic'" in msg, msg


@pytest.mark.parametrize("field", ["specular", "palette_blend"])
def test_a_switch_takes_true_or_false_only_and_its_refusal_names_it(field):
    """specular and palette_blend are bools: both accepted, 0/1/"true" refused with a
    message that names the field, the value and what is allowed (true or false)."""
    for value in (True, False):
        assert getattr(Config(**{field: value}), field) is value
    for value in (0, 1, "true", None):
        with pytest.raises(ConfigError) as e:
            Config(**{field: value})
        msg = str(e.value)
        assert e.value.field == field
        assert msg.startswith(field) and repr(value) in msg and "true or false" in msg, msg


def test_replace_lists_every_unknown_field_sorted_and_changes_only_what_it_is_given():
    """replace refuses unknown fields, naming all of them sorted (the first is ``field``);
    otherwise it is the Config with those fields changed, validated again."""
    with pytest.raises(ConfigError) as e:
        Config().replace(zeta=1, alpha=2, angle_bits=12)
    assert e.value.field == "alpha"
    assert str(e.value).endswith(": alpha, zeta"), str(e.value)
    base = Config(angle_bits=12, frac_bits=13, ks=0.25)
    assert base.replace(lights=3) == Config(angle_bits=12, frac_bits=13, ks=0.25, lights=3)
    assert base.replace() == base
    with pytest.raises(ConfigError) as e:              # B = 9 is below k - 1 = 13 at 16 bits
        Config(angle_bits=12, frac_bits=9).replace(angle_bits=16)
    assert e.value.field == "frac_bits"
