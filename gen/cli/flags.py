"""Command-line flags for the Config fields and a user's bump map, shared by every
subcommand."""

import argparse
import dataclasses

from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.scenes import GEOMETRIES
from bumprtl.sim.scenes.config import SceneConfig, flag_name, load_scene_config
from bumprtl.sim.scenes.usermap import CONVENTIONS, DEFAULT_HEIGHT_SCALE

__all__ = ["add_config_flags", "config_from_args", "add_map_flags", "map_overrides", "MAP_FLAGS",
           "scene_from_args"]

# Scene keys with a flag of their own (add_map_flags), in the order of the help.
MAP_FLAGS = ("height_map", "normal_map", "normal_convention", "geometry", "height_scale",
             "resample", "texture_size")


def add_config_flags(parser, fields=None):
    """``--angle-bits``, ``--frac-bits``, ... for the Config fields (all by default).

    Defaults are None, so :func:`config_from_args` can tell "not given" from a value and
    fall back to the Config default; the help text shows that default.
    """
    defaults = Config()
    for f in dataclasses.fields(Config):
        if fields is not None and f.name not in fields:
            continue
        flag = "--" + f.name.replace("_", "-")
        default = getattr(defaults, f.name)
        if isinstance(default, bool):
            parser.add_argument(flag, dest=f.name, action=argparse.BooleanOptionalAction,
                                default=None, help=f"default: {default}")
        else:
            parser.add_argument(flag, dest=f.name, type=type(default), default=None,
                                metavar=f.name.upper(), help=f"default: {default}")


def config_from_args(args, base=None):
    """A validated Config from the flags that were given (the rest keep their defaults)."""
    given = {f.name: getattr(args, f.name) for f in dataclasses.fields(Config)
             if getattr(args, f.name, None) is not None}
    return (base or Config()).replace(**given)


def config_flags_only(args, own, where):
    """Refuse a Config flag given in ``args`` that is not among ``own`` (the flags a unit
    reads, ``Unit.flags``): accepted, it would change nothing but the record of the Config.
    ``where`` names the command in the one-line refusal (``emit rotation``)."""
    for f in dataclasses.fields(Config):
        if getattr(args, f.name, None) is not None and f.name not in own:
            flags = ", ".join(flag_name(k) for k in own)
            raise BumpError(f"{flag_name(f.name)} does not apply to {where} (its Config "
                            f"flags: {flags})")


def add_map_flags(parser):
    """``--height-map``, ``--normal-map`` and the keys that go with a user's map (the scene
    keys of sim/scenes/config.py; defaults None so a flag that contradicts a scene file is caught)."""
    g = parser.add_argument_group("your own bump map (sim/scenes/usermap.py)")
    g.add_argument("--height-map", default=None, metavar="FILE",
                   help="height map: 8- or 16-bit greyscale PNG (white = 1.0) or .npy array "
                        "of heights; normals by Tarini's least-squares plane fit (Sec. 4.1)")
    g.add_argument("--normal-map", default=None, metavar="FILE",
                   help="tangent-space normal map: 8-bit RGB PNG (or (T, T, 3) .npy), "
                        "re-normalized; red = +x right, blue = +z out of the surface")
    g.add_argument("--normal-convention", default=None, choices=CONVENTIONS,
                   help="green channel of --normal-map: opengl = +Y up the image, directx = "
                        "+Y down (default: opengl)")
    g.add_argument("--geometry", default=None, choices=GEOMETRIES,
                   help="surface the map is wrapped on (default: the scene's own; a map: plane)")
    g.add_argument("--height-scale", type=float, default=None, metavar="S",
                   help=f"texels of relief for height 1.0 of --height-map (default: "
                        f"{DEFAULT_HEIGHT_SCALE:g})")
    g.add_argument("--resample", action="store_true", default=None,
                   help="resample a map that is not square with a power-of-two side in "
                        "[16, 4096] (or not --texture-size) instead of refusing it; a map is "
                        "never cropped")
    if not any(a.dest == "texture_size" for a in parser._actions):
        g.add_argument("--texture-size", type=int, default=None, metavar="T",
                       help="bump map size T, a power of two in [16, 4096] (default: the "
                            "map's size, or the scene's)")


def map_overrides(args):
    """The map flags that were given, as scene keys."""
    return {k: getattr(args, k) for k in MAP_FLAGS if getattr(args, k, None) is not None}


_SCENE_KEYS = {f.name for f in dataclasses.fields(SceneConfig)}


def scene_from_args(args, source, extra=None, defaults=None, flags=None):
    """The SceneConfig of ``source`` (a built-in name or a TOML file) with the Config and
    map flags that were given (and ``extra`` keys; ``defaults`` where nothing sets a key);
    a flag that contradicts a key the source sets is an error naming both, never a silent
    override. ``flags``: the flag that set each ``extra`` key, for messages."""
    given = {f.name: getattr(args, f.name) for f in dataclasses.fields(Config)
             if getattr(args, f.name, None) is not None}
    for key in given:
        if key not in _SCENE_KEYS:
            raise BumpError(f"{flag_name(key)} does not apply to a scene: the scene decides it "
                            f"({source!r}); its keys are in sim/scenes/config.py")
    scene = load_scene_config(source, {**given, **map_overrides(args), **(extra or {})},
                              flags=flags, defaults=defaults)
    _map_flags_have_a_map(args, scene)
    return scene


def _map_flags_have_a_map(args, scene):
    """A flag that only qualifies a user's map (its convention, its height scale, its
    resampling) without that map in the scene would change nothing: refused."""
    needs = {"normal_convention": ("a normal map (--normal-map)", scene.normal_map),
             "height_scale": ("a height map (--height-map)", scene.height_map),
             "resample": ("a map (--height-map, --normal-map)", scene.height_map or scene.normal_map)}
    for key, (what, present) in needs.items():
        if getattr(args, key, None) is not None and not present:
            raise BumpError(f"{flag_name(key)} applies to {what}, and the scene has none")
