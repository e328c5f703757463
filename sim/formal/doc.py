"""docs/formal.md: what is proved, how, and the table ``make formal`` printed."""

from pathlib import Path

from bumprtl.sim.formal.run import table

__all__ = ["write_doc"]

BEGIN, END = "<!-- formal table: begin -->", "<!-- formal table: end -->"


def write_doc(path, rows, args=""):
    """Replace the table between the markers of ``path`` (the prose around it stays)."""
    path = Path(path)
    command = f"make formal   (python -m bumprtl.sim.formal.run {args})".rstrip()
    block = f"{BEGIN}\nProduced by `{command.strip()}`:\n\n{table(rows)}\n{END}"
    text = path.read_text() if path.exists() else f"# Formal proofs\n\n{BEGIN}\n{END}\n"
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        text = head + block + rest.split(END, 1)[1]
    else:
        text = text.rstrip() + "\n\n" + block + "\n"
    path.write_text(text)
    return path
