"""Generated pages: their sections (each page's record is rtl.config.Config.made_at)."""

from pathlib import Path

__all__ = ["write_section"]


def write_section(path, name, text):
    """Replace the ``name`` section of a generated markdown file (between its markers),
    appending it when absent; other sections stay as they are."""
    path = Path(path)
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    old = path.read_text() if path.is_file() else "# Benchmarks\n"
    block = f"{begin}\n{text}\n{end}"
    if begin in old and end in old:
        new = old[:old.index(begin)] + block + old[old.index(end) + len(end):]
    else:
        new = old.rstrip("\n") + "\n\n" + block + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(new)
