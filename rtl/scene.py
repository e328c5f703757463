"""What a scene needs, and so what the generator builds (docs/architecture.md, "Scenes
decide what is built").

A :class:`SceneConfig` comes from a TOML file (``bumprtl emit pipeline --scene FILE``) or a
built-in name (:data:`BUILTIN`). Every key is checked at load time; a bad one raises a
:class:`BumpError` that names the key and its allowed values. The Config of the datapath
widths follows from the scene (:meth:`SceneConfig.config`).
"""

import tomllib
from dataclasses import dataclass, fields, asdict
from pathlib import Path

from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.methods import PER_PIXEL

__all__ = ["SceneConfig", "SceneError", "BUILTIN", "load_scene_config", "ADDRESSING",
           "BUMP_MAPS", "SHADINGS", "ROTATIONS", "light_fields"]

ADDRESSING = ("wrap", "clamp")
BUMP_MAPS = ("varying", "flat")          # does N' change from texel to texel?
SHADINGS = ("per-pixel", "palette")      # Lee/exact per-pixel rotation, or Tarini's palette
ROTATIONS = ("per-pixel", "per-polygon", "none")
_CONFIG_KEYS = ("method", "angle_bits", "frac_bits", "tag_bits", "spec_exponent",
                "spec_index_bits", "ka", "kd", "ks", "lights", "specular", "palette_size")


class SceneError(BumpError):
    """A scene file or built-in scene with a bad key; the message names the key."""


@dataclass(frozen=True)
class SceneConfig:
    """The switches of one scene class.

    Parameters
    ----------
    name : str
        Label of the scene class (sidecar, docs/scenes.md).
    image : str
        The procedural scene of ``bumprtl.sim.scenes`` rendered with it (``bumprtl render``).
    lights : int
        Number of lights, 1 to 8; they share one rotated normal.
    specular : bool
        Build the H path and the specular table.
    bump_map : str
        ``varying`` (a bump vector map in block RAM, fetched per pixel) or ``flat`` (one N'
        per polygon: no map, the rotation of N' happens once per polygon).
    shading : str
        ``per-pixel`` (rotation + illumination per pixel) or ``palette`` (Tarini et al.: a
        per-texel palette index and a colour-table lookup, no per-pixel rotation).
    rotation : str or None
        ``per-pixel``, ``per-polygon`` or ``none``; derived from ``bump_map`` and ``shading``
        when omitted, and an error when it contradicts them.
    texture : bool
        The scene has a colour texture: build the colour-texture blend.
    texture_size : int
        Bump map (and colour texture) size T, a power of two in [16, 4096].
    addressing : str
        ``wrap`` or ``clamp`` for texel coordinates outside the map.
    mip_levels : int
        Levels of the bump map in block RAM, 1 (no mipmaps) to log2(T) + 1.
    method, angle_bits, frac_bits, tag_bits, spec_exponent, spec_index_bits, ka, kd, ks,
    palette_size :
        Passed to :class:`Config` (checked there).
    """

    name: str = "default"
    image: str = "bricks"
    lights: int = 1
    specular: bool = True
    bump_map: str = "varying"
    shading: str = "per-pixel"
    rotation: str | None = None
    texture: bool = False
    texture_size: int = 64
    addressing: str = "wrap"
    mip_levels: int = 1
    method: str = "exact"
    angle_bits: int = 12
    frac_bits: int = 13
    tag_bits: int = 16
    spec_exponent: int = 16
    spec_index_bits: int = 10
    ka: float = 0.1
    kd: float = 0.7
    ks: float = 0.2
    palette_size: int = 256

    def __post_init__(self):
        for key in ("name", "image"):
            if not isinstance(getattr(self, key), str):
                raise SceneError(f"{key} must be a string, got {getattr(self, key)!r}")
        for key, allowed in (("bump_map", BUMP_MAPS), ("shading", SHADINGS),
                             ("addressing", ADDRESSING)):
            _choice(key, getattr(self, key), allowed)
        for key in ("specular", "texture"):
            if not isinstance(getattr(self, key), bool):
                raise SceneError(f"{key} must be true or false, got {getattr(self, key)!r}")
        if isinstance(self.lights, int) and not isinstance(self.lights, bool) and self.lights < 1:
            raise SceneError(f"lights = {self.lights}: a scene needs at least one light (allowed [1, 8])")
        t = self.texture_size
        if isinstance(t, bool) or not isinstance(t, int) or not 16 <= t <= 4096 or t & (t - 1):
            raise SceneError(f"texture_size must be a power of two in [16, 4096] (texel "
                             f"addressing by bit slicing), got {t!r}")
        top = t.bit_length()                   # log2(T) + 1 levels down to 1 x 1
        if isinstance(self.mip_levels, bool) or not isinstance(self.mip_levels, int) \
                or not 1 <= self.mip_levels <= top:
            raise SceneError(f"mip_levels must be an integer in [1, {top}] for texture_size "
                             f"{t}, got {self.mip_levels!r}")
        try:
            self.config
        except BumpError as e:
            raise SceneError(f"scene {self.name!r}: {e}") from None
        if self.method not in PER_PIXEL:
            raise SceneError(f"method must be one of {', '.join(PER_PIXEL)} in a scene (the "
                             f"baselines are built for the cost comparison only), got {self.method!r}")
        self._check_rotation()
        if self.rotation == "per-polygon" and self.method != "exact":
            raise SceneError(f"bump_map = 'flat' needs method = 'exact' (its rotation of N' once "
                             f"per polygon is the exact method's n''), got {self.method!r}")
        if self.lights > 1 and self.method != "exact" and self.shading == "per-pixel":
            raise SceneError(f"lights = {self.lights} needs method = 'exact' (lights share the one "
                             f"rotated normal n''; the lee method rotates each light instead)")

    def _check_rotation(self):
        derived = self.derived_rotation
        if self.rotation is None:
            object.__setattr__(self, "rotation", derived)
            return
        _choice("rotation", self.rotation, ROTATIONS)
        if self.rotation != derived:
            why = {"palette": "shading = 'palette' looks normals up in a colour table"}.get(
                self.shading, f"bump_map = {self.bump_map!r}")
            raise SceneError(f"rotation = {self.rotation!r} is impossible with {why}: "
                             f"allowed rotation = {derived!r}")

    @property
    def derived_rotation(self):
        if self.shading == "palette":
            return "none"
        return "per-pixel" if self.bump_map == "varying" else "per-polygon"

    @property
    def config(self) -> Config:
        """The datapath Config of this scene (widths, method, lights, terms)."""
        return Config(**{k: getattr(self, k) for k in _CONFIG_KEYS},
                      palette_blend=self.texture and self.shading == "palette")

    @property
    def texture_bits(self):
        return self.texture_size.bit_length() - 1

    @property
    def scene(self):
        """The ``--scene`` argument that reproduces this scene (a built-in name or a path)."""
        return self.name

    def to_dict(self):
        return asdict(self)

    def replace(self, **changes):
        return load_scene_config({**self.to_dict(), **changes, "rotation": changes.get("rotation")})


def light_fields(scene: SceneConfig):
    """Payload names of each light's vectors: ``("l", "h")`` for light 0, ``("l1", "h1")``..."""
    names = []
    for j in range(scene.lights):
        suffix = "" if j == 0 else str(j)
        names.append((f"l{suffix}",) + ((f"h{suffix}",) if scene.specular else ()))
    return names


def _choice(key, value, allowed):
    if value not in allowed:
        raise SceneError(f"{key} must be one of {', '.join(allowed)}, got {value!r}")


_KEYS = tuple(f.name for f in fields(SceneConfig))

# The scene classes of docs/scenes.md.
BUILTIN = {
    "default": {"name": "default"},
    "full": {"name": "full", "lights": 2, "texture": True, "mip_levels": 2},
    "diffuse": {"name": "diffuse", "specular": False},
    "two-lights": {"name": "two-lights", "lights": 2},
    "flat": {"name": "flat", "bump_map": "flat"},
    "palette": {"name": "palette", "shading": "palette"},
    "textured": {"name": "textured", "texture": True, "image": "bricks"},
}


def load_scene_config(source) -> SceneConfig:
    """A SceneConfig from a built-in name, a TOML path, or a dict of keys."""
    if isinstance(source, SceneConfig):
        return source
    if isinstance(source, dict):
        keys, where = dict(source), "scene"
    elif str(source) in BUILTIN:
        keys, where = dict(BUILTIN[str(source)]), f"built-in scene {source!r}"
    else:
        path = Path(source)
        if not path.is_file():
            raise SceneError(f"scene must be a TOML file or one of {', '.join(BUILTIN)}, "
                             f"got {str(source)!r}")
        try:
            keys = tomllib.loads(path.read_text())
        except tomllib.TOMLDecodeError as e:
            raise SceneError(f"scene file {path}: not valid TOML ({e})") from None
        keys.setdefault("name", str(path))      # names the file in the emit command line
        where = f"scene file {path}"
    unknown = sorted(set(keys) - set(_KEYS))
    if unknown:
        raise SceneError(f"unknown key {unknown[0]!r} in {where}: allowed keys are {', '.join(_KEYS)}")
    keys = {k: v for k, v in keys.items() if v is not None}
    return SceneConfig(**keys)
