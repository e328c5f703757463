"""The formal tooling's refusals that no other test reached (docs/coverage.md's per-branch
list): an unknown target, property or mutation is named with the ones allowed, before
anything is built or run."""

import types

import pytest

from bumprtl.gen.formal import run
from bumprtl.sim.formal.contract import PROPERTIES, StreamContract
from bumprtl.sim.formal.mutants import EDGE_MUTATIONS, BrokenEdge
from bumprtl.sim.formal.targets import TARGETS, target


def test_target_returns_the_named_target_and_names_the_allowed_ones_otherwise():
    name = next(iter(TARGETS))
    assert target(name) is TARGETS[name]
    with pytest.raises(KeyError, match=f"formal target must be one of {name}.*got 'nowhere'"):
        target("nowhere")


def test_execute_refuses_an_unknown_target_in_one_line_before_running(tmp_path, capsys):
    out = tmp_path / "formal"
    assert run.execute(units=["nowhere"], out=out) == 2
    captured = capsys.readouterr()
    [line] = captured.err.strip().splitlines()
    assert line.startswith("error: unknown formal target 'nowhere'") and next(iter(TARGETS)) in line
    assert not out.exists()


def test_contract_refuses_an_unknown_property():
    dut = types.SimpleNamespace(latency=1)
    with pytest.raises(ValueError, match="property must be one of .*got 'fast'") as e:
        StreamContract(dut, "fast")
    assert all(p in str(e.value) for p in PROPERTIES)


def test_bank_contract_refuses_a_unit_without_a_config():
    assert "bank" in PROPERTIES
    with pytest.raises(ValueError, match="bank: a PaletteLUT without the blend stage"):
        StreamContract(types.SimpleNamespace(latency=1), "bank")


def test_broken_edge_refuses_an_unknown_mutation():
    with pytest.raises(ValueError, match="mutation must be one of .*got 'never'") as e:
        BrokenEdge(None, 3, "never")
    assert all(m in str(e.value) for m in EDGE_MUTATIONS)


@pytest.mark.filterwarnings("ignore::amaranth.hdl.UnusedElaboratable")
@pytest.mark.parametrize("prop, message", [
    ("ready", "ready: the unit has no fifo_depth"),
    ("credit", "credit: the unit has no credit edge and chain to check"),
])
def test_ready_and_credit_refuse_a_unit_built_without_its_credit_edge(prop, message):
    """A unit built for inside a chain (credit=False) has neither a FIFO depth nor a credit
    edge: the two properties about them are refused while the contract is built, not
    handed to the solver."""
    from amaranth.hdl import Fragment

    from bumprtl.rtl.config import Config
    from bumprtl.rtl.illumination import Illumination

    with pytest.raises(ValueError, match=message):
        Fragment.get(StreamContract(Illumination(Config(), credit=False), prop), None)
