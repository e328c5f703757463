"""Stream payload layouts shared by the units (docs/architecture.md, Interfaces), all derived from a Config."""

from amaranth.hdl import Shape, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import SPEC_FRAC_BITS

__all__ = ["angle_shape", "polar_layout", "pixel_layout", "shade_layout", "layout_fields"]


def angle_shape(cfg: Config):
    """A binary angle: full circle = 2**angle_bits (docs/architecture.md, Number formats)."""
    return unsigned(cfg.angle_bits)


def polar_layout(cfg: Config):
    """A direction in polar angles: phi (azimuth), theta (from +z)."""
    return data.StructLayout({"phi": angle_shape(cfg), "theta": angle_shape(cfg)})


def pixel_layout(cfg: Config):
    """Per-pixel inputs of the rotation unit: world N, L, H and tangent-space bump normal
    N' (``b``), plus the side-band tag. H is present only when the Config has specular."""
    fields = {"n": polar_layout(cfg), "l": polar_layout(cfg)}
    if cfg.specular:
        fields["h"] = polar_layout(cfg)
    fields["b"] = polar_layout(cfg)
    fields["tag"] = unsigned(cfg.tag_bits)
    return data.StructLayout(fields)


def shade_layout(cfg: Config, fine=True):
    """Per-pixel outputs of the illumination unit: 8-bit diffuse, specular and Phong sum,
    and (``fine``) the unrounded terms the light sum and the texture blend take:
    ``diffuse_fine`` = clamp(N'.L', 0, 1) with B fractional bits and ``specular_fine`` =
    255 (N'.H')^n with SPEC_FRAC_BITS (rtl/shade.py). A light sum's output has no fine
    terms (``fine=False``)."""
    out = unsigned(cfg.out_bits)
    fields = {"diffuse": out, "specular": out, "color": out}
    if fine:
        fields["diffuse_fine"] = unsigned(cfg.frac_bits + 1)
        fields["specular_fine"] = unsigned(cfg.out_bits + SPEC_FRAC_BITS)
    return data.StructLayout({**fields, "tag": unsigned(cfg.tag_bits)})


def layout_fields(layout, prefix=""):
    """Bit fields of a payload layout, flattened: ``{name: [offset, width, signed]}``.

    Nested layouts get dotted names (``"l.phi"``). Testbenches pack and unpack payloads
    from this table, so they never hard-code a bit position.
    """
    out = {}
    for name, field in layout:
        shape = field.shape
        if isinstance(shape, data.Layout):
            for sub, (off, width, sgn) in layout_fields(shape, f"{prefix}{name}.").items():
                out[sub] = [field.offset + off, width, sgn]
        else:
            s = Shape.cast(shape)
            out[f"{prefix}{name}"] = [field.offset, s.width, s.signed]
    return out
