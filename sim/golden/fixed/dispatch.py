"""Dispatch to the bit-exact golden model of a unit by method: one entry point for the
tests, testbenches and benchmarks."""

from bumprtl.rtl.config import Config

__all__ = ["rotation_fixed", "illumination_fixed", "datapath_fixed", "encode_pixels"]


def _methods(cfg):
    if cfg.method == "exact":
        from bumprtl.sim.golden.fixed import exact as m
        return m.exact_rotation_fixed, m.exact_illumination_fixed
    if cfg.method == "lee":
        from bumprtl.sim.golden.fixed import lee as m
        return m.lee_rotation_fixed, m.lee_illumination_fixed
    # Baselines (rtl/baselines/<name>.py): sim/golden/fixed_<name>.py
    import importlib
    m = importlib.import_module(f"bumprtl.sim.golden.fixed.{cfg.method}")
    return m.rotation_fixed, m.illumination_fixed


def rotation_fixed(codes, cfg: Config):
    """VectorRotation's output fields (flattened names) from the input angle codes."""
    return _methods(cfg)[0](codes, cfg)


def illumination_fixed(rot, cfg: Config):
    """Illumination's output (diffuse, specular, color, ndotl, ndoth) from rotation fields."""
    return _methods(cfg)[1](rot, cfg)


def datapath_fixed(codes, cfg: Config):
    rot = rotation_fixed(codes, cfg)
    return {**rot, **illumination_fixed(rot, cfg)}




def encode_pixels(px, cfg: Config):
    """Float64 pixels -> the input codes of ``cfg.method``'s setup unit: binary angles for
    the polar methods (exact, lee, kim), Cartesian components for Peercy and Ernst (their
    module's ``encode``: what a Cartesian rasterizer would interpolate)."""
    import importlib
    from bumprtl.sim.golden.fixed.common import quantize_pixels
    if cfg.method in ("exact", "lee"):
        return quantize_pixels(px, cfg)
    m = importlib.import_module(f"bumprtl.sim.golden.fixed.{cfg.method}")
    return m.encode(px, cfg) if hasattr(m, "encode") else quantize_pixels(px, cfg)
