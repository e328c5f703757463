"""What the rule-set contracts share (sim/formal/sdram.py's JEDEC command rules,
sim/formal/axi.py's AXI4 read-channel rules, and the stream contract's inputs): the
component's inputs as the model's free inputs, and assertions named by the rule they check,
so that a failing location reported by sby reads as its rule."""

from amaranth.hdl import Assert, Cover, Elaboratable, Value, ValueCastable
from amaranth.lib import wiring

__all__ = ["component_inputs", "RuleContract"]


def component_inputs(dut):
    """Every ``In`` member of ``dut``'s signature, as a Value: the solver drives them."""
    ports = []
    for _path, member, value in dut.signature.flatten(dut):
        if member.flow == wiring.In:
            ports.append(value.as_value() if isinstance(value, ValueCastable) else Value.cast(value))
    return ports


class RuleContract(Elaboratable):
    """A formal wrapper around ``self.dut`` whose assertions are rules of ``RULES`` (rule ->
    message, set by the subclass); ``messages`` maps each assertion's ``file:line`` to its
    rule, ``covers`` lists what the covers show."""

    RULES = {}

    def __init__(self, dut):
        self.dut = dut
        self.messages = {}
        self.covers = []

    def free_inputs(self):
        return component_inputs(self.dut)

    def describe(self, location):
        """The rule sby reports at ``location`` (``file:line ...``)."""
        return self.messages.get(location.split(" ")[0], location)

    def _check(self, m, rule, test):
        check = Assert(test, self.RULES[rule], src_loc_at=1)
        self.messages[f"{check.src_loc[0]}:{check.src_loc[1]}"] = rule
        m.d.comb += check

    def _cover(self, m, what, test):
        self.covers.append(what)
        m.d.comb += Cover(test)
