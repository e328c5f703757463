"""What a scene needs, and so what the generator builds (docs/architecture.md, "Scenes
decide what is built").

A :class:`SceneConfig` comes from a TOML file (``bumprtl emit pipeline --scene FILE``) or a
built-in name (:data:`BUILTIN`). Every key is checked at load time; a bad one raises a
:class:`BumpError` that names the key and its allowed values. The Config of the datapath
widths follows from the scene (:meth:`SceneConfig.config`).
"""

import math
import tomllib
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from bumprtl.rtl.cache import SCENE_KEYS, scene_geometry
from bumprtl.rtl.config import TWO_LIGHT_WIDTHS, BumpError, Config
from bumprtl.rtl.methods import PER_PIXEL, get
from bumprtl.rtl.scene import (
    ADDRESSING,
    BUMP_MAPS,
    CACHE_DEFAULTS,
    ROTATIONS,
    SHADINGS,
    HardwareScene,
    MapSize,
    check_choice,
    check_map_memory,
    check_map_size,
    derived_rotation,
)
from bumprtl.sim.scenes import GEOMETRIES, SCENES
from bumprtl.sim.scenes.usermap import CONVENTIONS, DEFAULT_HEIGHT_SCALE, map_size

__all__ = ["SceneConfig", "SceneError", "BUILTIN", "load_scene_config", "ADDRESSING",
           "BUMP_MAPS", "SHADINGS", "ROTATIONS", "MAP_KEYS", "flag_name"]

MAP_KEYS = ("height_map", "normal_map")  # a user's map file instead of a procedural image
_CONFIG_KEYS = ("method", "angle_bits", "frac_bits", "tag_bits", "spec_exponent",
                "spec_index_bits", "ka", "kd", "ks", "lights", "specular", "palette_size")


class SceneError(BumpError):
    """A scene file or built-in scene with a bad key; the message names the key."""


@dataclass(frozen=True)
class SceneConfig(MapSize):
    """The switches of one scene class: the hardware's (:attr:`hardware`, an
    ``rtl/scene.HardwareScene``) with the map's source and the geometry.

    Parameters
    ----------
    name : str
        Label of the scene class (sidecar, docs/scenes.md).
    image : str or None
        The procedural scene of ``bumprtl.sim.scenes`` (``SCENES``) whose bump map the
        pipeline holds and ``bumprtl render`` draws; None with a user's map.
    height_map, normal_map : str or None
        A user's map file instead of ``image`` (at most one; sim/scenes/usermap.py): an 8- or
        16-bit greyscale PNG or a ``.npy`` of heights, or an 8-bit RGB tangent-space normal
        map PNG. In a TOML file a relative path is relative to the TOML file. The map's
        width becomes ``texture_size`` (a power of two in [16, 4096]) and a non-square
        map's height ``texture_height``.
    normal_convention : str
        ``opengl`` (green = +Y up the image, the default) or ``directx`` (green = +Y down).
    geometry : str or None
        ``plane``, ``sphere`` or ``cylinder``; None: the image's own (a user map: plane).
    height_scale : float
        Texels of relief for height 1.0 (white) of a height map (default 4).
    resample : bool
        Resample a map whose size is not allowed (or not ``texture_size``) instead of
        refusing it; a map is never cropped.
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
        Bump map (and colour texture) width W (the side T of a square map), a power of two in
        [16, 4096]; u runs over it.
    texture_height : int or None
        The map's height H, a power of two in [16, W]; v runs over it (a sphere: the
        colatitude, so W = 2H is an equirectangular map). None: W, a square map.
    addressing : str
        ``wrap`` or ``clamp`` for texel coordinates outside the map.
    mip_levels : int
        Levels of the bump map, 1 (no mipmaps) to log2(H) + 1.
    map_memory : str
        ``bram`` (the map in block RAM, the default) or ``axi`` (the map in the user's
        memory, read through a texel cache with an AXI4 port: docs/memory.md).
    cache_sets, cache_ways, cache_block, axi_data_bits : int
        ``axi``: the cache's sets, ways, line block side (powers of two) and AXI data width
        (32 or 64); defaults 64, 2, 4, 32 (rtl/scene.CACHE_DEFAULTS).
    cache_queue, cache_outstanding : int
        ``axi``: pixels the cache's in-order queue holds (a power of two in [2, 1024],
        default 256) and AXI bursts outstanding at most (a power of two in [1, 64], default
        64).
    method, angle_bits, frac_bits, tag_bits, spec_exponent, spec_index_bits, ka, kd, ks,
    palette_size :
        Passed to :class:`Config` (checked there).
    """

    name: str = "default"
    image: str | None = "bricks"
    lights: int = 1
    specular: bool = True
    bump_map: str = "varying"
    shading: str = "per-pixel"
    rotation: str | None = None
    texture: bool = False
    texture_size: int = 64
    texture_height: int | None = None
    addressing: str = "wrap"
    mip_levels: int = 1
    map_memory: str = "bram"
    cache_sets: int = CACHE_DEFAULTS["cache_sets"]
    cache_ways: int = CACHE_DEFAULTS["cache_ways"]
    cache_block: int = CACHE_DEFAULTS["cache_block"]
    axi_data_bits: int = CACHE_DEFAULTS["axi_data_bits"]
    cache_queue: int = CACHE_DEFAULTS["cache_queue"]
    cache_outstanding: int = CACHE_DEFAULTS["cache_outstanding"]
    # Config's fields and defaults (rtl/config.py is the one source of both)
    method: str = Config.method
    angle_bits: int = Config.angle_bits
    frac_bits: int = Config.frac_bits
    tag_bits: int = Config.tag_bits
    spec_exponent: int = Config.spec_exponent
    spec_index_bits: int = Config.spec_index_bits
    ka: float = Config.ka
    kd: float = Config.kd
    ks: float = Config.ks
    palette_size: int = Config.palette_size
    height_map: str | None = None
    normal_map: str | None = None
    normal_convention: str = "opengl"
    geometry: str | None = None
    height_scale: float = DEFAULT_HEIGHT_SCALE
    resample: bool = False

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise SceneError(f"name must be a string, got {self.name!r}", "name")
        self._check_picture()
        for key, allowed in (("bump_map", BUMP_MAPS), ("shading", SHADINGS),
                             ("addressing", ADDRESSING)):
            _choice(key, getattr(self, key), allowed)
        for key in ("specular", "texture", "resample"):
            if not isinstance(getattr(self, key), bool):
                raise SceneError(f"{key} must be true or false, got {getattr(self, key)!r}", key)
        if isinstance(self.lights, int) and not isinstance(self.lights, bool) and self.lights < 1:
            raise SceneError(f"lights = {self.lights}: a scene needs at least one light (allowed [1, 8])",
                             "lights")
        check_map_size(self.texture_size, self.mip_levels, SceneError, self.texture_height)
        if not self.square and self.shading == "palette":
            raise SceneError(f"texture_height = {self.texture_height} (a {self.texture_size} x "
                             f"{self.texture_height} map) needs shading = 'per-pixel': the "
                             f"palette's normal quantizer and index mipmaps (Tarini Sec. 4-5) "
                             f"take square maps; allowed texture_height = {self.texture_size} "
                             f"or none", "texture_height")
        check_map_memory(self.map_memory, self.shading, self.bump_map, self.texture,
                         {k: getattr(self, k) for k in CACHE_DEFAULTS}, SceneError)
        if self.map_memory == "axi":
            try:
                scene_geometry(self.hardware)        # the cache's keys, checked now
            except BumpError as e:
                key = SCENE_KEYS.get(e.field, e.field)
                raise SceneError(f"scene {self.name!r}: {key}: {e}", key) from None
        try:
            _ = self.config       # derive it now: a bad width is the scene's error
        except BumpError as e:
            raise SceneError(f"scene {self.name!r}: {e}", e.field) from None
        if self.method not in PER_PIXEL:
            raise SceneError(f"method must be one of {', '.join(PER_PIXEL)} in a scene (the "
                             f"baselines are built for the cost comparison only), got {self.method!r}", "method")
        self._check_rotation()
        rotates_normal = get(self.method).rotates_normal
        allowed = " or ".join(repr(n) for n in PER_PIXEL if get(n).rotates_normal)
        if self.rotation == "per-polygon" and not rotates_normal:
            raise SceneError(f"bump_map = 'flat' needs method = {allowed} (its rotation of N' once "
                             f"per polygon is the rotated normal n''), got {self.method!r}",
                             "bump_map")
        if self.lights > 1 and not rotates_normal and self.shading == "per-pixel":
            raise SceneError(f"lights = {self.lights} needs method = {allowed} (lights share the "
                             f"one rotated normal n''; the {self.method} method rotates each light "
                             f"instead)", "lights")

    def _check_picture(self):
        """image, or one user map (then image is None), and the keys that go with them."""
        maps = [k for k in MAP_KEYS if getattr(self, k) is not None]
        for key in maps:
            if not isinstance(getattr(self, key), str) or not getattr(self, key):
                raise SceneError(f"{key} must be a file path (a string), got {getattr(self, key)!r}", key)
        if len(maps) > 1:
            raise SceneError("give height_map or normal_map, not both: a height map becomes "
                             "normals by the plane fit, a normal map already is one")
        if maps:
            object.__setattr__(self, "image", None)
        elif not isinstance(self.image, str) or self.image not in SCENES:
            raise SceneError(f"image must be one of {', '.join(SCENES)} (or give height_map "
                             f"or normal_map for your own map), got {self.image!r}", "image")
        _choice("normal_convention", self.normal_convention, CONVENTIONS)
        if self.geometry is not None:
            _choice("geometry", self.geometry, GEOMETRIES)
        h = self.height_scale
        if isinstance(h, bool) or not isinstance(h, (int, float)) or not 0 < h < math.inf:
            raise SceneError(f"height_scale must be a positive finite number (texels of relief "
                             f"for height 1.0), got {h!r}", "height_scale")
        if maps and self.bump_map == "flat" and self.shading != "palette":
            raise SceneError(f"{maps[0]} needs bump_map = 'varying': a flat bump map (one N' "
                             f"per polygon) stores no map")

    @property
    def map_file(self):
        """``(key, path)`` of the user's map, or None."""
        for key in MAP_KEYS:
            if getattr(self, key) is not None:
                return key, getattr(self, key)
        return None

    @property
    def picture(self):
        """What the bump map shows: the user's map file or the procedural image's name."""
        return self.map_file[1] if self.map_file else self.image

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
                             f"allowed rotation = {derived!r}", "rotation")

    @property
    def derived_rotation(self):
        return derived_rotation(self.shading, self.bump_map)

    @property
    def config(self) -> Config:
        """The datapath Config of this scene (widths, method, lights, terms)."""
        return Config(**{k: getattr(self, k) for k in _CONFIG_KEYS},
                      palette_blend=self.texture and self.shading == "palette")

    @property
    def hardware(self) -> HardwareScene:
        """The switches the hardware reads (rtl/scene.py): what BumpPipeline, BumpMapFetch
        and BoardCore are built from; the map's source and the geometry stay here."""
        return HardwareScene(name=self.name, shading=self.shading, bump_map=self.bump_map,
                             rotation=self.rotation, texture=self.texture,
                             texture_size=self.texture_size,
                             texture_height=self.texture_height, addressing=self.addressing,
                             mip_levels=self.mip_levels, map_memory=self.map_memory,
                             **{k: getattr(self, k) for k in CACHE_DEFAULTS},
                             config=self.config)

    @property
    def scene(self):
        """The ``--scene`` argument that reproduces this scene (a built-in name or a path)."""
        return self.name

    def to_dict(self):
        return asdict(self)

    def replace(self, **changes):
        """A copy with some keys changed (validated again); a new map replaces the picture."""
        keys = self.to_dict()
        if any(changes.get(k) is not None for k in MAP_KEYS):
            keys.update(image=None, **{k: None for k in MAP_KEYS})
        return load_scene_config({**keys, **changes, "rotation": changes.get("rotation")})


def _choice(key, value, allowed):
    check_choice(key, value, allowed, SceneError)


def flag_name(key):
    """The command-line flag of scene key ``key``."""
    return "--" + key.replace("_", "-")


_KEYS = tuple(f.name for f in fields(SceneConfig))

# The two-light scenes take the widths that prove 1 LSB on every channel with two lights.
_TWO_LIGHTS = dict(zip(("angle_bits", "frac_bits"), TWO_LIGHT_WIDTHS, strict=False))

# The scene classes of docs/scenes.md.
BUILTIN = {
    "default": {"name": "default"},
    "full": {"name": "full", "lights": 2, "texture": True, "mip_levels": 2, **_TWO_LIGHTS},
    "diffuse": {"name": "diffuse", "specular": False},
    "two-lights": {"name": "two-lights", "lights": 2, **_TWO_LIGHTS},
    "flat": {"name": "flat", "bump_map": "flat"},
    "palette": {"name": "palette", "shading": "palette"},
    "textured": {"name": "textured", "texture": True, "image": "bricks"},
}


_PICTURE_KEYS = ("image", *MAP_KEYS)       # what the map shows: one of them


def _source_keys(source):
    """``(keys, where)`` of a built-in name, a TOML path or a dict; map paths of a TOML file
    made relative to the file's directory."""
    if isinstance(source, dict):
        return dict(source), "scene"
    if str(source) in BUILTIN:
        return dict(BUILTIN[str(source)]), f"built-in scene {source!r}"
    path = Path(source)
    if not path.is_file():
        raise SceneError(f"scene must be a TOML file or one of {', '.join(BUILTIN)}, "
                         f"got {str(source)!r}")
    try:
        keys = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise SceneError(f"scene file {path}: not valid TOML ({e})") from None
    keys.setdefault("name", str(path))          # names the file in the emit command line
    for key in MAP_KEYS:
        if isinstance(keys.get(key), str):
            keys[key] = str(path.parent / keys[key]) if not Path(keys[key]).is_absolute() \
                else keys[key]
    return keys, f"scene file {path}"


def _merge(keys, where, overrides, flags):
    """``keys`` plus the command-line ``overrides``; a flag that contradicts a key the source
    sets is an error naming both (never a silent override)."""
    flags = flags or {}
    for key, value in overrides.items():
        flag = flags.get(key, flag_name(key))
        if key in _PICTURE_KEYS:
            clash = [k for k in _PICTURE_KEYS if k != key and keys.get(k) is not None]
            if clash:
                raise SceneError(f"{flag} {value} contradicts {clash[0]} = {keys[clash[0]]!r} in "
                                 f"{where}: give the picture once")
        if key in keys and keys[key] is not None and keys[key] != value:
            raise SceneError(f"{flag} {value} contradicts {key} = {keys[key]!r} in {where}: "
                             f"drop one")
    return {**keys, **overrides}


def load_scene_config(source, overrides=None, flags=None, defaults=None) -> SceneConfig:
    """A SceneConfig from a built-in name, a TOML path, or a dict of keys.

    ``overrides``: scene keys given on the command line (``{key: value}``; ``flags`` names
    their flags for messages). A key the source sets to another value is an error naming
    both. ``defaults``: keys used when neither sets them (``texture_size`` not with a map).
    With a user map (``height_map``/``normal_map``) ``texture_size`` is the map's side (or,
    given, must equal it unless ``resample``) and ``image`` is not allowed."""
    if isinstance(source, SceneConfig):
        if not overrides:
            return source
        source = {**source.to_dict(), "rotation": None}
    keys, where = _source_keys(source)
    unknown = sorted(set(keys) - set(_KEYS))
    if unknown:
        raise SceneError(f"unknown key {unknown[0]!r} in {where}: allowed keys are {', '.join(_KEYS)}")
    keys = _merge({k: v for k, v in keys.items() if v is not None}, where,
                  {k: v for k, v in (overrides or {}).items() if v is not None}, flags)
    maps = [k for k in MAP_KEYS if k in keys]
    for key, value in (defaults or {}).items():
        if key not in keys and value is not None and not (maps and key == "texture_size"):
            keys[key] = value
    if maps:
        if "image" in keys:
            raise SceneError(f"image = {keys['image']!r} and {maps[0]} in {where}: give the "
                             f"picture once")
        defaults = SceneConfig()
        extra = [k for k, need in (("height_scale", "height_map"), ("normal_convention",
                 "normal_map")) if keys.get(k, getattr(defaults, k)) != getattr(defaults, k)
                 and need not in keys]
        if extra:
            raise SceneError(f"{extra[0]} applies to a {'height' if extra[0] == 'height_scale' else 'normal'}"
                             f" map, but {where} gives {maps[0]}")
        if len(maps) == 1 and isinstance(keys[maps[0]], str):
            resample = keys.get("resample", False) is True
            keys["texture_size"] = map_size(keys[maps[0]], resample, keys.get("texture_size"),
                                            maps[0].split("_")[0], keys.get("texture_height"))
    return SceneConfig(**keys)
