"""Stream payload layouts shared by the units (docs/architecture.md, Interfaces), all derived from a Config."""

from amaranth.hdl import Shape, unsigned
from amaranth.lib import data

from bumprtl.rtl.config import Config
from bumprtl.rtl.tables import SPEC_FRAC_BITS

__all__ = ["angle_shape", "polar_layout", "light_layout", "light_fields", "light_keys",
           "pixel_layout", "shade_layout", "layout_fields", "pack", "unpack"]


def angle_shape(cfg: Config):
    """A binary angle: full circle = 2**angle_bits (docs/architecture.md, Number formats)."""
    return unsigned(cfg.angle_bits)


def polar_layout(cfg: Config):
    """A direction in polar angles: phi (azimuth), theta (from +z)."""
    return data.StructLayout({"phi": angle_shape(cfg), "theta": angle_shape(cfg)})


def light_layout(cfg: Config):
    """One light's vectors in polar angles: L (``l``) and, with specular, H (``h``)."""
    fields = {"l": polar_layout(cfg)}
    if cfg.specular:
        fields["h"] = polar_layout(cfg)
    return data.StructLayout(fields)


def light_fields(cfg: Config):
    """The per-light input fields of a pipeline with ``cfg.lights`` lights: light 0's L and H
    are ``l`` and ``h`` (:func:`pixel_layout`'s, so they ride through the rotation unit),
    lights 1..m-1 are ``extra_lights``, an ``ArrayLayout`` of m - 1 :func:`light_layout`
    (element j - 1 is light j; absent with one light). In this order the bits are light 0,
    light 1, ... one after the other."""
    fields = {name: field.shape for name, field in light_layout(cfg)}
    if cfg.lights > 1:
        fields["extra_lights"] = data.ArrayLayout(light_layout(cfg), cfg.lights - 1)
    return fields


def light_keys(cfg: Config):
    """Per light j, ``{one-light key: pipeline key}`` of its angles in the flattened payload
    (:func:`layout_fields`' names, as the golden models and stimulus files key them): light 0
    ``{"l.phi": "l.phi", ...}``, light 1 ``{"l.phi": "extra_lights.0.l.phi", ...}``. Read off
    :func:`light_fields`, whose bits hold the lights one after the other."""
    own = list(layout_fields(light_layout(cfg)))
    names = list(layout_fields(data.StructLayout(light_fields(cfg))))
    k = len(own)
    return [dict(zip(own, names[j * k:(j + 1) * k], strict=False)) for j in range(cfg.lights)]


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


def pack(fields, values):
    """Pack ``{field: int}`` into one integer; negative values are two's complement."""
    word = 0
    for name, (offset, width, _signed) in fields.items():
        v = int(values.get(name, 0))
        lo, hi = (-(1 << (width - 1)), (1 << (width - 1)) - 1) if _signed else (0, (1 << width) - 1)
        if width and not lo <= v <= hi:
            raise ValueError(f"payload field {name} = {v} does not fit {width} bits")
        word |= (v & ((1 << width) - 1)) << offset
    return word


def unpack(fields, word):
    """Inverse of :func:`pack`: ``{field: int}`` with signed fields sign-extended."""
    out = {}
    for name, (offset, width, _signed) in fields.items():
        v = (word >> offset) & ((1 << width) - 1)
        if _signed and width and v >> (width - 1):
            v -= 1 << width
        out[name] = v
    return out
