"""HardwareScene: the switches of one scene that decide what the hardware builds.

:class:`~bumprtl.rtl.pipeline.BumpPipeline`, :class:`~bumprtl.rtl.bumpfetch.BumpMapFetch`
and :class:`~bumprtl.rtl.board.BoardCore` take one; the units they build (fetch, rotation,
illumination, palette, texture blend) read its ``config``. Where the map comes from (a
procedural image or a user's file, its height scale, resampling) and the surface the
renderer draws are not the hardware's: ``sim/scenes/config.SceneConfig`` holds those and
composes a HardwareScene (``SceneConfig.hardware``).

A bad value raises a one-line :class:`BumpError` naming the field and its allowed values.
"""

from dataclasses import dataclass

from bumprtl.rtl.config import BumpError, Config

__all__ = ["HardwareScene", "MapSize", "ADDRESSING", "BUMP_MAPS", "SHADINGS", "ROTATIONS",
           "TEXTURE_SIZES", "MAP_MEMORIES", "CACHE_DEFAULTS", "check_map_memory", "derived_rotation", "check_scene", "check_choice",
           "check_map_size"]

ADDRESSING = ("wrap", "clamp")
BUMP_MAPS = ("varying", "flat")          # does N' change from texel to texel?
SHADINGS = ("per-pixel", "palette")      # Lee/exact per-pixel rotation, or Tarini's palette
ROTATIONS = ("per-pixel", "per-polygon", "none")
TEXTURE_SIZES = (16, 4096)               # a power of two in this range
MAP_MEMORIES = ("bram", "axi")           # the map in block RAM, or behind a cache on AXI4
# The texel cache of map_memory = "axi" (rtl/cache.CacheGeometry): sets, ways, side of a
# line's square block of texels, AXI data bits. 64 x 2 lines of 4 x 4 texels: 8 KiB of
# 28-bit texels in 4-byte slots, a line one 16-beat burst on a 32-bit bus. Pixels its
# in-order queue holds (a power of two in [2, 1024]) and AXI bursts outstanding at most (a
# power of two in [1, 64]): what hides the memory's latency (docs/memory.md).
CACHE_DEFAULTS = {"cache_sets": 64, "cache_ways": 2, "cache_block": 4, "axi_data_bits": 32,
                  "cache_queue": 256, "cache_outstanding": 64}


def derived_rotation(shading, bump_map):
    """The rotation of N' that ``shading`` and ``bump_map`` imply."""
    if shading == "palette":
        return "none"
    return "per-pixel" if bump_map == "varying" else "per-polygon"


def check_scene(unit, scene):
    """``scene`` itself when it is a :class:`HardwareScene`; else a one-line TypeError
    naming ``unit``'s class (a SceneConfig gives its ``hardware``), ``unit`` silenced so
    that the half-built component raises no unused-elaboratable warning."""
    if not isinstance(scene, HardwareScene):
        unit._MustUse__silence = True
        raise TypeError(f"{type(unit).__name__} takes a HardwareScene (rtl/scene.py; a "
                        f"SceneConfig's is its hardware), got {type(scene).__name__}")
    return scene


def check_choice(key, value, allowed, error=BumpError):
    """``value`` of ``key`` is one of ``allowed``; else ``error`` (a BumpError class) naming
    the key and the allowed values."""
    if value not in allowed:
        raise error(f"{key} must be one of {', '.join(allowed)}, got {value!r}", key)


def check_map_memory(map_memory, shading, bump_map, texture, cache=None, error=BumpError):
    """``map_memory`` is one of :data:`MAP_MEMORIES`; ``axi`` (rtl/cache.py) holds a
    per-texel map without a colour texture: a varying N' map with per-pixel shading, or
    the palette's index map; the ``cache`` keys (:data:`CACHE_DEFAULTS`) other than their
    defaults need ``axi``; else ``error`` naming the key (rtl/cache.CacheGeometry checks
    their ranges)."""
    check_choice("map_memory", map_memory, MAP_MEMORIES, error)
    for key, value in (cache or {}).items():
        if map_memory != "axi" and value != CACHE_DEFAULTS[key]:
            raise error(f"{key} = {value!r} applies to map_memory = 'axi' (the texel cache), "
                        f"the scene has map_memory = {map_memory!r}", key)
    if map_memory != "axi":
        return
    if texture:
        raise error("map_memory = 'axi' needs texture = false (the colour texture stays in "
                    "block RAM beside a map in block RAM): allowed otherwise map_memory = "
                    "'bram'", "map_memory")
    if shading == "per-pixel" and bump_map != "varying":
        raise error("map_memory = 'axi' needs a map: bump_map = 'varying' with shading = "
                    "'per-pixel', or shading = 'palette' (got bump_map = 'flat'); allowed "
                    "otherwise map_memory = 'bram'", "map_memory")


def check_map_size(texture_size, mip_levels, error=BumpError, texture_height=None):
    """The map's width T is a power of two in :data:`TEXTURE_SIZES`, its height
    ``texture_height`` (None: T, a square map) a power of two in [16, T], and ``mip_levels``
    in [1, log2(min(W, H)) + 1] (every level at least one texel on its shorter side); else
    ``error`` (a BumpError class) naming the key and its range."""
    t, (lo, hi) = texture_size, TEXTURE_SIZES
    if isinstance(t, bool) or not isinstance(t, int) or not lo <= t <= hi or t & (t - 1):
        raise error(f"texture_size must be a power of two in [{lo}, {hi}] (texel "
                    f"addressing by bit slicing), got {t!r}", "texture_size")
    h = t if texture_height is None else texture_height
    if isinstance(h, bool) or not isinstance(h, int) or not lo <= h <= t or h & (h - 1):
        raise error(f"texture_height must be a power of two in [{lo}, {t}] (the map's height, "
                    f"at most its width texture_size = {t}), got {h!r}", "texture_height")
    top = h.bit_length()                   # log2(H) + 1 levels down to 1 texel high
    if isinstance(mip_levels, bool) or not isinstance(mip_levels, int) \
            or not 1 <= mip_levels <= top:
        size = f"texture_size {t}" if h == t else f"a {t} x {h} map"
        raise error(f"mip_levels must be an integer in [1, {top}] for {size}, got "
                    f"{mip_levels!r}", "mip_levels")


class MapSize:
    """The map's size from a scene's ``texture_size`` (the width W) and ``texture_height``
    (the height H, None for a square map): the one place HardwareScene and
    sim/scenes/config.SceneConfig derive it, for the RTL, the golden models and the benches."""

    @property
    def texture_bits(self):
        """log2 of ``texture_size``, the map's width."""
        return self.texture_size.bit_length() - 1

    @property
    def map_height(self):
        """The map's height H: ``texture_height``, or ``texture_size`` (a square map)."""
        return self.texture_size if self.texture_height is None else self.texture_height

    @property
    def height_bits(self):
        """log2 of :attr:`map_height`."""
        return self.map_height.bit_length() - 1

    @property
    def square(self):
        return self.map_height == self.texture_size

    @property
    def map_label(self):
        """The map's size as messages write it: ``T^2``, or ``W x H``."""
        return f"{self.texture_size}^2" if self.square else f"{self.texture_size} x {self.map_height}"

    def level_size(self, level):
        """``(width, height)`` of mip ``level``: (W >> l, H >> l)."""
        return self.texture_size >> level, self.map_height >> level


@dataclass(frozen=True)
class HardwareScene(MapSize):
    """What the hardware of one scene builds.

    Parameters
    ----------
    name : str
        Label of the scene (error messages).
    shading : str
        ``per-pixel`` (rotation + illumination per pixel) or ``palette`` (a per-texel
        palette index and a colour-table lookup).
    bump_map : str
        ``varying`` (a map in block RAM, fetched per pixel) or ``flat`` (one N' per polygon).
    rotation : str or None
        ``per-pixel``, ``per-polygon`` or ``none``; None: :func:`derived_rotation`; any
        other value than the derived one is an error.
    texture : bool
        Build the colour texture memory and its blend.
    texture_size : int
        Map width W (the side T of a square map), a power of two in :data:`TEXTURE_SIZES`
        (texel addressing by bit slicing); u runs over it.
    texture_height : int or None
        Map height H, a power of two in [16, W]; v runs over it. None: W (a square map);
        :attr:`map_height` is the height either way.
    addressing : str
        ``wrap`` or ``clamp`` for texel coordinates outside the map.
    mip_levels : int
        Levels of the map, 1 to log2(H) + 1; level l is (W >> l) x (H >> l) texels.
    map_memory : str
        ``bram`` (the map in block RAM, :class:`~bumprtl.rtl.bumpfetch.BumpMapFetch`) or
        ``axi`` (the map in the user's memory behind a texel cache with an AXI4 read port,
        :class:`~bumprtl.rtl.cache.AxiMapFetch`; a varying N' map with per-pixel shading
        or the palette's index map, no colour texture).
    cache_sets, cache_ways, cache_block, axi_data_bits : int
        With ``map_memory = "axi"``: the texel cache's sets, ways a set, side of a line's
        square block of texels (powers of two) and AXI data width (32 or 64);
        :data:`CACHE_DEFAULTS`.
    cache_queue, cache_outstanding : int
        With ``map_memory = "axi"``: pixels the cache's queue holds (a power of two in
        [2, 1024], default 256) and AXI bursts outstanding at most (a power of two in
        [1, 64], default 64).
    config : Config
        The datapath widths, method, lights, specular, terms and palette size.
    """

    name: str = "default"
    shading: str = "per-pixel"
    bump_map: str = "varying"
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
    config: Config = Config()

    def __post_init__(self):
        if not isinstance(self.config, Config):
            raise BumpError(f"config must be a Config, got {type(self.config).__name__}", "config")
        for key, allowed in (("shading", SHADINGS), ("bump_map", BUMP_MAPS),
                             ("addressing", ADDRESSING)):
            check_choice(key, getattr(self, key), allowed)
        if not isinstance(self.texture, bool):
            raise BumpError(f"texture must be true or false, got {self.texture!r}", "texture")
        check_map_size(self.texture_size, self.mip_levels, texture_height=self.texture_height)
        check_map_memory(self.map_memory, self.shading, self.bump_map, self.texture,
                         {k: getattr(self, k) for k in CACHE_DEFAULTS})
        derived = derived_rotation(self.shading, self.bump_map)
        if self.rotation is None:
            object.__setattr__(self, "rotation", derived)
        elif self.rotation != derived:
            check_choice("rotation", self.rotation, ROTATIONS)
            raise BumpError(f"rotation = {self.rotation!r} is impossible with shading = "
                            f"{self.shading!r}, bump_map = {self.bump_map!r}: allowed rotation = "
                            f"{derived!r}", "rotation")

    def replace(self, **changes):
        """A copy with some switches or Config fields changed (both checked again)."""
        own = {k: changes.pop(k) for k in list(changes) if k in self.__dataclass_fields__}
        config = own.pop("config", self.config)
        if changes:
            config = config.replace(**changes)
        keys = {k: getattr(self, k) for k in self.__dataclass_fields__}
        return HardwareScene(**{**keys, "rotation": None, **own, "config": config})

    @property
    def lights(self):
        return self.config.lights

    @property
    def specular(self):
        return self.config.specular

    @property
    def angle_bits(self):
        return self.config.angle_bits

    @property
    def tag_bits(self):
        return self.config.tag_bits
