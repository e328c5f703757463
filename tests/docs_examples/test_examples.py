"""docs/examples/: the commands of its README run as written (the Verilog top behind the
`bumprtl vectors` bench on Icarus passes), and the Amaranth top matches the golden model
in the Amaranth simulator; each example fails when its map load is broken."""

import importlib.util
import re
import shlex
import subprocess
from pathlib import Path

import pytest

from bumprtl.gen.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "docs" / "examples"


def _first_sh_block(text):
    return re.search(r"```sh\n(.*?)```", text, re.S).group(1).strip().splitlines()


def _run_readme_block(lines, out, top_source=None):
    """Run the README's lines with ``build/example`` moved to ``out``: ``bumprtl`` in this
    process, ``cd`` as a change of directory, the rest in a shell. Returns the last
    command's output lines."""
    cwd, stdout = ROOT, ""
    for line in lines:
        line = line.replace("build/example", str(out))
        if top_source is not None:
            line = line.replace("docs/examples/bump_top.v", str(top_source))
        argv = shlex.split(line)
        if argv[0].endswith("bumprtl"):
            assert main(argv[1:]) == 0, line
        elif argv[0] == "cd":
            cwd = cwd / argv[1]
        else:
            r = subprocess.run(line, shell=True, cwd=cwd, capture_output=True, text=True,
                               timeout=600)
            assert r.returncode == 0, (line, r.stderr[-2000:])
            stdout = r.stdout
    return stdout.splitlines()


def test_readme_verilog_commands_pass_on_icarus(tmp_path):
    lines = _first_sh_block((EXAMPLES / "README.md").read_text())
    assert any(ln.startswith("iverilog -g2005") for ln in lines)
    out = _run_readme_block(lines, tmp_path / "example")
    assert out[-1] == "PASS 300", out
    # a top that writes every word one address off loads a wrong map: the bench sees it
    broken = (EXAMPLES / "bump_top.v").read_text().replace(
        "map_w_addr <= addr[ADDR_BITS-1:0];", "map_w_addr <= addr[ADDR_BITS-1:0] + 1'b1;")
    assert broken != (EXAMPLES / "bump_top.v").read_text()
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "bump_top.v").write_text(broken)
    again = [ln for ln in lines if "bumprtl " not in ln]        # the same design and vectors
    out = _run_readme_block(again, tmp_path / "example", tmp_path / "broken" / "bump_top.v")
    assert out[-1].startswith("FAIL pixel "), out


def _amaranth_example():
    spec = importlib.util.spec_from_file_location("amaranth_top", EXAMPLES / "amaranth_top.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_amaranth_top_matches_the_golden_model(capsys):
    example = _amaranth_example()
    assert example.main(["--pixels", "8"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "PASS 8"


@pytest.mark.parametrize("bad", ["bump.map_w_en.eq(0)"])
def test_amaranth_top_without_its_map_fails(bad, tmp_path, capsys):
    """The check can fail: the same top with the map write disabled mismatches."""
    text = (EXAMPLES / "amaranth_top.py").read_text()
    broken = text.replace("bump.map_w_en.eq(~self.loaded & (addr < depth))", bad)
    assert broken != text
    (tmp_path / "broken.py").write_text(broken)
    spec = importlib.util.spec_from_file_location("broken_top", tmp_path / "broken.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--pixels", "4"]) == 1
    assert capsys.readouterr().out.startswith("FAIL pixel 0 field ")
