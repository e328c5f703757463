"""docs/formal.md: what is proved, how, and the table ``make formal`` printed."""

from bumprtl.gen.tools.docs import made_at, write_section
from bumprtl.rtl.config import Config

__all__ = ["write_doc", "table", "SECTION"]

SECTION = "formal table"       # the page's marked section (gen/tools/docs.markers)


def table(rows):
    """The proof table as Markdown (rows: gen/formal/run.py's Row)."""
    lines = ["| unit | property | result | depth | latency | lemmas | seconds |",
             "| --- | --- | --- | ---: | ---: | ---: | ---: |"]
    for r in rows:
        lines.append(f"| {r.unit} | {r.prop} | {r.result} | {r.depth} | {r.latency} | "
                     f"{r.lemmas} | {r.seconds:.1f} |")
    return "\n".join(lines)


def write_doc(path, rows, command="", seconds=None, checked=None):
    """Replace the table section of ``path`` (the prose around it stays); ``command``: the
    flags the run was given (with ``--merge``, the page names them); ``seconds``: the run's
    wall time, printed beside the command with ``checked`` (the checks it ran; default
    every row)."""
    if "--merge" in command.split():
        how = (f"Produced by `make formal` (`python -m bumprtl.gen.formal.run -j 2 --doc "
               f"docs/formal.md`; `bumprtl formal` is the same command); the rows it names "
               f"re-checked by `python -m bumprtl.gen.formal.run {command}`, the others kept "
               f"from the previous run's `results.json`")
    else:
        how = ("Produced by `make formal` (`python -m bumprtl.gen.formal.run -j 2 "
               "--doc docs/formal.md`; `bumprtl formal` is the same command)")
    if seconds is not None:
        checked = len(rows) if checked is None else checked
        how += f"; that run: {checked} checks in {seconds:.0f} s of wall time"
    record = made_at(Config(), "the default; each proof runs at the small widths of "
                               "sim/formal/targets.py")
    return write_section(path, SECTION, f"{how}.\n{record}:\n\n{table(rows)}", title="# Formal proofs")
