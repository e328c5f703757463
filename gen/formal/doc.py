"""docs/formal.md: what is proved, how, and the table ``make formal`` printed."""

from bumprtl.gen.tools.docs import made_at, write_section
from bumprtl.rtl.config import Config

__all__ = ["write_doc", "table", "SECTION", "AXI_SECTION", "axi_unit"]

SECTION = "formal table"       # the page's marked section (gen/tools/docs.markers)
AXI_SECTION = "formal axi table"   # the texel cache's: its AXI4 port, its pipeline
MAKE_FORMAL = ["-j", "2", "--doc", "docs/formal.md"]      # make formal's flags


def axi_unit(unit):
    """A row of the AXI section: the cache's AXI4 port (``cache_axi_*``), its broken
    managers (``mutant axi_*``) and a ``map_memory = "axi"`` pipeline (``*_axi``)."""
    return unit.startswith(("cache_axi_", "mutant axi_")) or unit.endswith("_axi")


def table(rows):
    """The proof table as Markdown (rows: gen/formal/run.py's Row)."""
    lines = ["| unit | property | result | depth | latency | lemmas | seconds |",
             "| --- | --- | --- | ---: | ---: | ---: | ---: |"]
    for r in rows:
        lines.append(f"| {r.unit} | {r.prop} | {r.result} | {r.depth} | {r.latency} | "
                     f"{r.lemmas} | {r.seconds:.1f} |")
    return "\n".join(lines)


def write_doc(path, rows, command="", seconds=None, checked=None):
    """Replace the table sections of ``path`` that ``rows`` have rows of (the stream
    contract's :data:`SECTION`, the texel cache's :data:`AXI_SECTION`: :func:`axi_unit`;
    the prose around them and a section without rows stay); ``command``: the flags the run
    was given (with ``--merge``, the page names them); ``seconds``: the run's wall time,
    printed beside the command with ``checked`` (the checks it ran; default every row)."""
    for name, part in ((SECTION, [r for r in rows if not axi_unit(r.unit)]),
                       (AXI_SECTION, [r for r in rows if axi_unit(r.unit)])):
        if part:
            _write_section(path, name, part, command, seconds, checked)
    return path


def _write_section(path, name, rows, command, seconds, checked):
    if "--merge" in command.split():
        how = (f"Produced by `make formal` (`python -m bumprtl.gen.formal.run -j 2 --doc "
               f"docs/formal.md`; `bumprtl formal` is the same command); the rows it names "
               f"re-checked by `python -m bumprtl.gen.formal.run {command}`, the others kept "
               f"from the previous run's `results.json`")
    elif command and "--from-results" not in command.split() and command.split() != MAKE_FORMAL:
        how = (f"Produced by `python -m bumprtl.gen.formal.run {command}` (`make formal` runs "
               f"these with every other check: `python -m bumprtl.gen.formal.run -j 2 --doc "
               f"docs/formal.md`)")
    else:
        how = ("Produced by `make formal` (`python -m bumprtl.gen.formal.run -j 2 "
               "--doc docs/formal.md`; `bumprtl formal` is the same command)")
    if seconds is not None:
        checked = len(rows) if checked is None else checked
        how += f"; that run: {checked} checks in {seconds:.0f} s of wall time"
    record = made_at(Config(), "the default; each proof runs at the small widths of "
                               "sim/formal/targets.py")
    return write_section(path, name, f"{how}.\n{record}:\n\n{table(rows)}", title="# Formal proofs")
