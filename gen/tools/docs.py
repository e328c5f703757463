"""Generated pages: their marked sections and the record of the configuration they were
made at.

Every generator that writes into a page of docs/ (the benches, the reports, the scenes
table, the formal proofs) replaces one section between its markers with
:func:`write_section` and names its configuration with :func:`made_at`'s line
(tests/test_docs_made_at.py holds every such line to today's default ``Config``).
"""

from pathlib import Path

__all__ = ["write_section", "markers", "made_at"]


def markers(name):
    """The two HTML comments around section ``name``: ``<!-- name:begin -->``, ``<!-- name:end -->``."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def write_section(path, name, text, title="# Benchmarks"):
    """Replace the ``name`` section of the generated Markdown page ``path`` (between its
    :func:`markers`) with ``text``, appending it when absent; a page that does not exist yet
    starts with the heading ``title``. The rest of the page stays as it is. Returns ``path``."""
    path = Path(path)
    begin, end = markers(name)
    old = path.read_text() if path.is_file() else title + "\n"
    block = f"{begin}\n{text}\n{end}"
    if begin in old and end in old:
        new = old[:old.index(begin)] + block + old[old.index(end) + len(end):]
    else:
        new = old.rstrip("\n") + "\n\n" + block + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(new)
    return path


def made_at(cfg, note=""):
    """The one-line record of the configuration ``cfg`` (a ``Config``) a generated page was
    made at: both widths, then ``note`` in parentheses when given."""
    return (f"Made at: angle_bits={cfg.angle_bits}, frac_bits={cfg.frac_bits}"
            + (f" ({note})" if note else ""))
