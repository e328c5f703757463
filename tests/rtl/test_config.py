import pytest

from bumprtl.rtl.config import Config, ConfigError


@pytest.mark.parametrize("field, value, words", [
    ("angle_bits", 3, ["angle_bits", "[4, 16]"]),
    ("angle_bits", 17, ["angle_bits", "[4, 16]"]),
    ("frac_bits", 8, ["frac_bits", "[9, 24]"]),       # default k = 10 needs B >= 9
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


def test_replace_validates_and_rejects_unknown_fields():
    with pytest.raises(ConfigError, match="frac_bits"):
        Config().replace(frac_bits=2)
    with pytest.raises(ConfigError, match="unknown Config field"):
        Config().replace(bits=3)
