"""What the netlist mutation harness (netlist.py, netlist_board.py) needs of a target: its top
module and its ports, as :class:`Design`.

A unit or pipeline target's Design is read from its emitted sidecar through
``bumprtl.rtl.sidecar.load`` (:meth:`Design.from_sidecar`: the sidecar's ``module`` is the
Yosys top); a board target, which has no sidecar, builds it from the Amaranth signals it
emits (:meth:`Design.from_signals`). Every target's run directory keeps its Design in
:data:`FILE` (:meth:`Design.dump`, :meth:`Design.load`), the one file ``--recheck`` reads:
a record of the harness, not a sidecar, in a shape no sidecar has (a list of ports), so
neither file can be taken for the other.
"""

import json
from dataclasses import dataclass
from pathlib import Path

from bumprtl.rtl.sidecar import Port
from bumprtl.rtl.sidecar import load as load_sidecar

FILE = "harness_ports.json"
FORMAT = "bumprtl netlist mutation harness: a target's top module and ports (not a sidecar)"


@dataclass(frozen=True)
class Design:
    """A target of the harness: ``module`` the Yosys top (also the shim's name) and
    ``ports`` name -> :class:`bumprtl.rtl.sidecar.Port` (``dir`` and ``width``; ``fields``
    always None: the harness drives and compares whole ports)."""
    module: str
    ports: dict

    @classmethod
    def from_sidecar(cls, path):
        """The Design of the emitted sidecar ``path`` (``bumprtl.rtl.sidecar.load``)."""
        side = load_sidecar(path)
        return cls(side.module, {n: Port(p.dir, p.width) for n, p in side.ports.items()})

    @classmethod
    def from_signals(cls, module, signals):
        """The Design of an Amaranth module converted with ``ports`` = the signals of
        ``signals`` (``[(signal, "in"|"out")]``), plus the clock and reset Amaranth adds."""
        ports = {"clk": Port("in", 1), "rst": Port("in", 1)}
        ports.update({s.name: Port(d, len(s)) for s, d in signals})
        return cls(module, ports)

    def names(self, direction):
        """The names of the ports of ``direction`` ("in"|"out"), sorted."""
        return sorted(n for n, p in self.ports.items() if p.dir == direction)

    def declaration(self, name):
        """The Verilog-2005 declaration of port ``name`` in a module header's body."""
        p = self.ports[name]
        rng = f"[{p.width - 1}:0] " if p.width > 1 else ""
        return f"  {'input' if p.dir == 'in' else 'output'} wire {rng}{name};"

    def dump(self, folder):
        """Write :data:`FILE` into ``folder``; returns its path."""
        path = Path(folder) / FILE
        path.write_text(json.dumps({"format": FORMAT, "module": self.module,
                                    "ports": [[n, p.dir, p.width]
                                              for n, p in sorted(self.ports.items())]},
                                   indent=1) + "\n")
        return path

    @classmethod
    def load(cls, folder):
        """The Design :meth:`dump` wrote into ``folder``; ValueError naming the file when it
        is not one (OSError when it is missing)."""
        path = Path(folder) / FILE
        match json.loads(path.read_text()):
            case {"format": str(f), "module": str(module), "ports": list(ports)} if f == FORMAT:
                pass
            case _:
                raise ValueError(f"{path}: not a harness record ({FORMAT})")
        if not all(isinstance(p, list) and len(p) == 3 and p[1] in ("in", "out") for p in ports):
            raise ValueError(f"{path}: a port is not [name, in|out, width]")
        return cls(module, {n: Port(d, int(w)) for n, d, w in ports})
