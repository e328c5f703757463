"""`bumprtl emit --fusesoc`: the CAPI2 core beside the Verilog, run through `fusesoc`
(its lint target is Verilator with the project's waivers; a lint problem fails it)."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.fusesoc import memory_files, vlnv
from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS, tool_env
from bumprtl.rtl.sidecar import load

FUSESOC = str(Path(sys.executable).parent / "fusesoc")


def _fusesoc(root, target, name):
    return subprocess.run([FUSESOC, "--cores-root", str(root), "run", "--build-root",
                           str(root / "fsbuild"), "--target", target, vlnv(name)],
                          capture_output=True, text=True, env=tool_env(), cwd=root)


def test_emitted_core_lints_and_builds_under_fusesoc(tmp_path, capsys):
    assert main(["emit", "sincos", "--angle-bits", "8", "--frac-bits", "8", "--fusesoc",
                 "--out", str(tmp_path)]) == 0
    core = (tmp_path / "bumprtl_sincos.core").read_text()
    assert core.startswith("CAPI=2:") and "bumprtl_sincos.v" in core
    version = load(tmp_path / "bumprtl_sincos.json").schema_version     # the one it carries
    assert f"# Sidecar bumprtl_sincos.json: schema_version {version} " in core
    assert all(f"-Wno-{w}" in core for w in VERILATOR_WAIVERS)
    for target in ("lint", "sim"):
        out = _fusesoc(tmp_path, target, "bumprtl_sincos")
        assert out.returncode == 0, out.stdout + out.stderr
    assert memory_files(tmp_path / "bumprtl_sincos.v") == []          # ROM contents are inline


def test_fusesoc_lint_target_fails_on_a_lint_problem(tmp_path):
    assert main(["emit", "sincos", "--angle-bits", "8", "--frac-bits", "8", "--fusesoc",
                 "--out", str(tmp_path)]) == 0
    v = tmp_path / "bumprtl_sincos.v"
    v.write_text(v.read_text().replace("endmodule", "  wire [3:0] narrow = 8'hff;\nendmodule", 1))
    out = _fusesoc(tmp_path, "lint", "bumprtl_sincos")
    assert out.returncode != 0 and "WIDTHTRUNC" in out.stdout + out.stderr


def test_readmemh_files_go_into_the_core(tmp_path):
    from bumprtl.gen.flow.fusesoc import write_core
    v = tmp_path / "rom.v"
    v.write_text('module rom; reg [7:0] m [0:3]; initial $readmemh("rom.hex", m); endmodule\n')
    (tmp_path / "rom.hex").write_text("00\n01\n02\n03\n")
    text = write_core(v, "test").read_text()
    assert "- rom.hex: {copyto: rom.hex}" in text and "filesets: [rtl, mem]" in text


def test_core_alone_runs_a_named_pipeline_with_its_memory_images(tmp_path):
    """``emit pipeline --name --ports named --load port --fusesoc``: the core lists the unit,
    its named-ports wrapper (the top level), the sidecar and the map image; copied alone
    into a fresh directory, its sim (Icarus) and lint targets run. Without the wrapper
    file in the core the sim build fails (the check can fail)."""
    out = tmp_path / "emit"
    assert main(["emit", "pipeline", "--scene", "default", "--texture-size", "16",
                 "--angle-bits", "10", "--frac-bits", "11", "--load", "port", "--name", "bm_a",
                 "--ports", "named", "--fusesoc", "--out", str(out)]) == 0
    core = (out / "bm_a.core").read_text()
    for f in ("bm_a.v", "bm_a_named.v", "- bm_a.json: {copyto: bm_a.json}",
              "- bm_a_map.hex: {copyto: bm_a_map.hex}", "toplevel: bm_a_named"):
        assert f in core, f
    listed = re.findall(r"^      - ([\w.]+)", core, re.M)
    alone = tmp_path / "alone"
    alone.mkdir()
    for f in ["bm_a.core", *listed]:
        shutil.copy(out / f, alone / f)
    assert sorted(p.name for p in alone.iterdir()) == sorted(p.name for p in out.iterdir())
    for target in ("sim", "lint"):
        run = _fusesoc(alone, target, "bm_a")
        assert run.returncode == 0, run.stdout + run.stderr
    copied = next((alone / "fsbuild").glob("*/sim-icarus"))
    assert (copied / "bm_a_map.hex").read_text() == (out / "bm_a_map.hex").read_text()
    broken = tmp_path / "broken"
    shutil.copytree(alone, broken, ignore=shutil.ignore_patterns("fsbuild"))
    (broken / "bm_a.core").write_text(core.replace("      - bm_a_named.v\n", ""))
    assert _fusesoc(broken, "sim", "bm_a").returncode != 0


def test_a_core_without_memory_files_has_the_rtl_fileset_only(tmp_path):
    """A unit with no $readmemh and no sidecar carried: no mem fileset, and the targets do
    not name one (FuseSoC refuses a target naming a fileset the core lacks)."""
    from bumprtl.gen.flow.fusesoc import write_core
    v = tmp_path / "inv.v"
    v.write_text("module inv(input a, output y); assign y = ~a; endmodule\n")
    text = write_core(v, "test").read_text()
    assert "- inv.v" in text and "filesets: [rtl]" in text
    assert "mem:" not in text and "[rtl, mem]" not in text
