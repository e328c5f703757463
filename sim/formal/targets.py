"""What ``make formal`` proves: every unit and every built-in scene pipeline, at small
widths (the properties are about the handshake; widths only change the payload).

A :class:`Target` builds a fresh unit per check (a unit elaborates once). Its tag is wide
enough that the tags in flight never alias (``2**tag_bits > fifo_depth + 1``: at most
``fifo_depth`` pixels are accepted and not delivered, one per credit), so a dropped or
duplicated pixel always shows in the order check.
"""

from collections.abc import Callable
from dataclasses import dataclass, field

from bumprtl.rtl.bumpfetch import BumpMapFetch
from bumprtl.rtl.config import Config
from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.palette import PaletteLUT
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.rtl.sincos import SinCos
from bumprtl.rtl.texture import TextureBlend
from bumprtl.sim.formal.axi import FORMAL_GEOMETRIES, PROVE_ONLY
from bumprtl.sim.golden.methods import BASELINES, HARDWARE, PER_PIXEL
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

__all__ = ["Target", "TARGETS", "SMALL", "SMALL_SCENE", "SMALL_CACHE", "AXI_STREAM", "AXI",
           "target"]

# Small datapath widths (Config checks B >= k - 1 and the table sizes).
SMALL = {"angle_bits": 6, "frac_bits": 6, "tag_bits": 4, "spec_index_bits": 4, "palette_size": 16}
SMALL_SCENE = {**SMALL, "texture_size": 16}

STREAM = ("hold", "ready", "order", "quiet", "latency", "credit", "cover", "hold_cover",
          "ready_cover", "order_cover", "quiet_cover", "latency_cover", "credit_cover")
# A map_memory = "axi" pipeline: the cache in front of the credit edge sets i.ready (its
# lookup, not the credits) and a miss waits for the memory, so neither ``ready`` (i.ready =
# fewer than fifo_depth in flight) nor ``latency`` (a fixed port_latency) is its contract.
AXI_STREAM = tuple(p for p in STREAM if not p.startswith(("ready", "latency")))
# The texel cache's AXI4 manager port (sim/formal/axi.py): every rule proved, every cover.
AXI = ("axi", "axi_cover")
# A small texel cache for the map_memory = "axi" pipeline (a flush of two cycles after
# reset; the queue and bursts outstanding small): the scene keys of rtl/scene.CACHE_DEFAULTS.
SMALL_CACHE = {"cache_sets": 2, "cache_ways": 2, "cache_block": 2, "cache_queue": 4,
               "cache_outstanding": 2}


@dataclass(frozen=True)
class Target:
    name: str
    build: Callable            # tag_bits -> unit
    props: tuple = STREAM
    note: str = ""
    slow: bool = False         # left out of the quick subset
    config: dict = field(default_factory=dict)

    def unit(self):
        """A fresh unit with a tag wide enough for its pixels in flight (a texel cache in
        front of the edge adds the pixels it holds)."""
        bits = SMALL["tag_bits"]
        dut = self.build(bits)
        while (1 << bits) <= dut.fifo_depth + getattr(dut, "front_capacity", 0) + 1:
            bits += 1
            _discard(dut)
            dut = self.build(bits)
        return dut


def _discard(dut):
    """A unit built only to read its latency: no UnusedElaboratable warning for it."""
    for unit in [dut, *getattr(dut, "units", {}).values()]:
        unit._MustUse__silence = True


def _cfg(bits, **kw):
    return Config(**{**SMALL, "tag_bits": bits, **kw})


def _sincos(bits):
    return SinCos(_cfg(bits))


def _rotation(method):
    def build(bits):
        return VectorRotation(_cfg(bits, method=method))
    return build


def _illumination(method):
    def build(bits):
        return Illumination(_cfg(bits, method=method))
    return build


def _palette(blend):
    def build(bits):
        return PaletteLUT(_cfg(bits, palette_blend=blend))
    return build


def _scene(name, bits, **more):
    keys = {**BUILTIN[name], **SMALL_SCENE, "tag_bits": bits, **more}
    return load_scene_config(keys)


def _fetch(bits):
    return BumpMapFetch(_scene("default", bits).hardware)


def _texture_blend(bits):
    return TextureBlend(_cfg(bits), lights=2)


def _pipeline(name, **more):
    def build(bits):
        return BumpPipeline(_scene(name, bits, **more).hardware)
    return build


def _no_unit(bits):
    raise ValueError("an AXI target is checked by sim/formal/axi.py, not built as a unit")


def _targets():
    out = [Target("sincos", _sincos)]
    # each distinct hardware once (HARDWARE: Ernst's is Peercy's, proved as peercy)
    for method in (m for m in PER_PIXEL if m in HARDWARE):
        out.append(Target(f"rotation_{method}", _rotation(method)))
        out.append(Target(f"illumination_{method}", _illumination(method)))
    for method in (m for m in BASELINES if m in HARDWARE):
        out.append(Target(f"rotation_{method}", _rotation(method), slow=True, note="baseline"))
        out.append(Target(f"illumination_{method}", _illumination(method), slow=True,
                          note="baseline"))
    out.append(Target("palette", _palette(False), STREAM + ("bank", "bank_cover")))
    out.append(Target("palette_blend", _palette(True)))
    out.append(Target("fetch", _fetch))
    out.append(Target("texture_blend", _texture_blend))
    for name in BUILTIN:
        palette = load_scene_config(BUILTIN[name]).shading == "palette"
        out.append(Target(f"pipeline_{name}", _pipeline(name),
                          STREAM + (("bank", "bank_cover") if palette else ()), slow=True,
                          note=f"scene {name}"))
    out.append(Target("pipeline_default_axi", _pipeline("default", map_memory="axi", **SMALL_CACHE),
                      AXI_STREAM, slow=True, note="scene default, map_memory = 'axi'"))
    # the cache's AXI4 port: a small cache and the default scene's own (sim/formal/axi.py)
    for geometry in FORMAL_GEOMETRIES:
        out.append(Target(f"cache_axi_{geometry}", _no_unit,
                          AXI[:1] if geometry in PROVE_ONLY else AXI, note="AXI4 read rules",
                          config={"geometry": geometry}))
    return out


TARGETS = {t.name: t for t in _targets()}


def target(name):
    if name not in TARGETS:
        raise KeyError(f"formal target must be one of {', '.join(TARGETS)}, got {name!r}")
    return TARGETS[name]
