"""docs/formal.md: what is proved, how, and the table ``make formal`` printed."""

from pathlib import Path

from bumprtl.rtl.config import Config

__all__ = ["write_doc", "table"]

BEGIN, END = "<!-- formal table: begin -->", "<!-- formal table: end -->"


def table(rows):
    """The proof table as Markdown (rows: sim/formal/run.py's Row)."""
    lines = ["| unit | property | result | depth | latency | lemmas | seconds |",
             "| --- | --- | --- | ---: | ---: | ---: | ---: |"]
    for r in rows:
        lines.append(f"| {r.unit} | {r.prop} | {r.result} | {r.depth} | {r.latency} | "
                     f"{r.lemmas} | {r.seconds:.1f} |")
    return "\n".join(lines)


def write_doc(path, rows, args=""):
    """Replace the table between the markers of ``path`` (the prose around it stays)."""
    path = Path(path)
    if "--merge" in args.split():
        how = (f"Produced by `make formal` (`python -m bumprtl.sim.formal.run -j 2 --doc "
               f"docs/formal.md`; `bumprtl formal` is the same command); the rows it names "
               f"re-checked by `python -m bumprtl.sim.formal.run {args}`, the others kept "
               f"from the previous run's `results.json`")
    else:
        how = ("Produced by `make formal` (`python -m bumprtl.sim.formal.run -j 2 "
               "--doc docs/formal.md`; `bumprtl formal` is the same command)")
    record = Config().made_at("the default; each proof runs at the small widths of "
                              "sim/formal/targets.py")
    block = f"{BEGIN}\n{how}.\n{record}:\n\n{table(rows)}\n{END}"
    text = path.read_text() if path.exists() else f"# Formal proofs\n\n{BEGIN}\n{END}\n"
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        text = head + block + rest.split(END, 1)[1]
    else:
        text = text.rstrip() + "\n\n" + block + "\n"
    path.write_text(text)
    return path
