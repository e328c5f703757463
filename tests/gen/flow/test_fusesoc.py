"""`bumprtl emit --fusesoc`: the CAPI2 core beside the Verilog, run through `fusesoc`
(its lint target is Verilator with the project's waivers; a lint problem fails it)."""

import subprocess
import sys
from pathlib import Path

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.fusesoc import memory_files, vlnv
from bumprtl.sim.toolchain import VERILATOR_WAIVERS, tool_env

FUSESOC = str(Path(sys.executable).parent / "fusesoc")


def _fusesoc(root, target, name):
    return subprocess.run([FUSESOC, "--cores-root", str(root), "run", "--build-root",
                           str(root / "fsbuild"), "--target", target, vlnv(name)],
                          capture_output=True, text=True, env=tool_env(), cwd=root)


def test_emitted_core_lints_and_builds_under_fusesoc(tmp_path, capsys):
    assert main(["emit", "sincos", "--angle-bits", "8", "--frac-bits", "8", "--fusesoc",
                 "--out", str(tmp_path)]) == 0
    core = (tmp_path / "sincos.core").read_text()
    assert core.startswith("CAPI=2:") and "sincos.v" in core
    assert all(f"-Wno-{w}" in core for w in VERILATOR_WAIVERS)
    for target in ("lint", "sim"):
        out = _fusesoc(tmp_path, target, "sincos")
        assert out.returncode == 0, out.stdout + out.stderr
    assert memory_files(tmp_path / "sincos.v") == []          # ROM contents are inline


def test_fusesoc_lint_target_fails_on_a_lint_problem(tmp_path):
    assert main(["emit", "sincos", "--angle-bits", "8", "--frac-bits", "8", "--fusesoc",
                 "--out", str(tmp_path)]) == 0
    v = tmp_path / "sincos.v"
    v.write_text(v.read_text().replace("endmodule", "  wire [3:0] narrow = 8'hff;\nendmodule", 1))
    out = _fusesoc(tmp_path, "lint", "sincos")
    assert out.returncode != 0 and "WIDTHTRUNC" in out.stdout + out.stderr


def test_readmemh_files_go_into_the_core(tmp_path):
    from bumprtl.gen.flow.fusesoc import write_core
    v = tmp_path / "rom.v"
    v.write_text('module rom; reg [7:0] m [0:3]; initial $readmemh("rom.hex", m); endmodule\n')
    (tmp_path / "rom.hex").write_text("00\n01\n02\n03\n")
    text = write_core(v, "test").read_text()
    assert "- rom.hex: {copyto: rom.hex}" in text and "filesets: [rtl, mem]" in text
