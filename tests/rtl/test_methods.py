"""The method registry (rtl/methods.py, the hardware; sim/golden/methods.py, the models of
the same names): the hardware registry is the list of names Config accepts and the models'
registry has one record per name, each record's classes are wiring.Components that
elaborate with the stream ports and layouts the record states, and a bad name is a
one-line ConfigError naming ``method``."""

import numpy as np
import pytest
from amaranth.lib import wiring

from bumprtl.rtl import methods as hardware
from bumprtl.rtl.config import Config, ConfigError
from bumprtl.rtl.illumination import Illumination
from bumprtl.rtl.layouts import shade_layout
from bumprtl.rtl.pipe import unit_memory_records
from bumprtl.rtl.rotation import VectorRotation
from bumprtl.sim.golden import methods
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.vectors import TINY

METHOD_NAMES = tuple(hardware.METHODS)


def test_registry_covers_every_method_name_once():
    assert tuple(methods.METHODS) == METHOD_NAMES == ("exact", "lee", "peercy", "ernst", "kim")
    assert all(name == m.name for name, m in methods.METHODS.items())
    assert len({m.title for m in methods.METHODS.values()}) == len(methods.METHODS)
    assert set(methods.PER_PIXEL) | set(methods.BASELINES) == set(METHOD_NAMES)
    assert not set(methods.PER_PIXEL) & set(methods.BASELINES)
    assert sorted(m.table1_column for m in methods.METHODS.values()) == sorted(
        {m.table1_column for m in methods.METHODS.values()})
    for name in METHOD_NAMES:
        assert methods.get(name) is methods.METHODS[name]
        assert methods.get(name).title == hardware.get(name).title      # the joined view
    assert tuple(methods.MODELS) == tuple(hardware.METHODS)    # one models' record per name


def test_ernst_builds_peercys_hardware_under_its_own_name():
    """Ernst is an alias: its own name and Table 1 column, Peercy's components and models;
    the distinct hardware (placed, proved, rendered) lists Peercy's once."""
    ernst, peercy = hardware.get("ernst"), hardware.get("peercy")
    assert ernst.hardware == "peercy" and peercy.hardware == "peercy"
    assert (ernst.rotation, ernst.illumination) == (peercy.rotation, peercy.illumination)
    assert ernst.table1_column != peercy.table1_column and ernst.title != peercy.title
    assert "ernst" not in hardware.HARDWARE and "peercy" in hardware.HARDWARE
    assert methods.get("ernst").reference is methods.get("peercy").reference


def test_unknown_method_names_method_and_the_choices():
    with pytest.raises(ConfigError) as e:
        methods.get("nope")
    text = str(e.value)
    assert "\n" not in text and "method" in text and "'nope'" in text
    assert all(name in text for name in METHOD_NAMES)
    with pytest.raises(ConfigError, match="method must be one of exact, lee"):
        Config(method="nope")


@pytest.mark.parametrize("name", METHOD_NAMES)
def test_each_method_elaborates_with_its_layouts(name):
    """Both classes are wiring.Components with stream ports, chosen by the entry points;
    the rotation's output is the record's ``rotated_layout`` and the illumination's input."""
    m = methods.get(name)
    cfg = TINY.replace(method=name)
    rotation, illumination = VectorRotation(cfg), Illumination(cfg)
    assert type(rotation) is m.rotation and type(illumination) is m.illumination
    for unit in (rotation, illumination):
        assert isinstance(unit, wiring.Component) and unit.latency >= 1
        before = dict(vars(unit))
        _, records = unit_memory_records(unit)         # elaborates; records its memories
        assert vars(unit).keys() == before.keys()      # elaborate sets nothing on the unit
        assert all(size["bits"] == size["depth"] * size["width"] for size in records.of(unit).values())
    assert rotation.o.payload.shape() == m.rotated_layout(cfg) == illumination.i.payload.shape()
    assert illumination.o.payload.shape() == shade_layout(cfg)


@pytest.mark.parametrize("name", METHOD_NAMES)
def test_each_method_golden_models_run(name):
    """encode -> rotation_fixed -> illumination_fixed gives 8-bit shades; the dispatch by
    ``cfg.method`` is the record's; the bound is an int and the float64 reference runs."""
    m = methods.get(name)
    cfg = Config(method=name)
    px = PixelInputs.random(50, np.random.default_rng(1))
    out = methods.datapath_fixed(methods.encode_pixels(px, cfg), cfg)
    assert out.keys() == m.datapath_fixed(m.encode(px, cfg), cfg).keys()
    assert all(0 <= int(v) <= 255 for k in ("diffuse", "specular", "color") for v in out[k])
    assert isinstance(m.predicted_error_bound_lsb(cfg), int) and m.error_note
    assert m.reference(px, cfg).diffuse.shape == (50,)


def test_the_registries_refuse_unknown_and_duplicate_methods_naming_method(monkeypatch):
    """Both registries' lookups name ``method`` and the allowed names; a name registered
    twice, hardware with no models' record and a hardware path outside rtl/ are refused."""
    with pytest.raises(ConfigError) as e:
        hardware.get("nosuch")
    assert e.value.field == "method"
    assert str(e.value) == f"method must be one of {', '.join(hardware.METHODS)}, got 'nosuch'"
    with pytest.raises(ConfigError, match="method 'exact' is registered already"):
        hardware.register(hardware.METHODS["exact"])
    assert list(hardware.METHODS).count("exact") == 1
    with pytest.raises(ValueError, match="'os.path:join' must name an attribute of a bumprtl.rtl"):
        hardware._resolve("os.path:join")
    with pytest.raises(ValueError, match="must name an attribute"):
        hardware._resolve("bumprtl.rtl.rotation")
    monkeypatch.setitem(hardware.METHODS, "toy-no-models", hardware.METHODS["exact"])
    with pytest.raises(ConfigError, match="method 'toy-no-models' has hardware .* but no "
                                          "models' record") as e:
        methods.get("toy-no-models")
    assert e.value.field == "method"
    assert not hasattr(methods.get("exact"), "__nosuch__")     # dunders are not the hardware's


def test_a_method_built_on_anothers_hardware_names_that_hardware():
    shared = [m for m in hardware.METHODS.values() if m.hardware_of]
    assert shared, "no method shares another's hardware"
    for m in shared:
        assert m.hardware == m.hardware_of != m.name and m.hardware_of in hardware.HARDWARE
    assert hardware.METHODS["exact"].hardware == "exact"
