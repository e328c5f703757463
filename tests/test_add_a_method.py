"""Adding a method touches the registry only: a toy method (tests/tools/toy_method.py: the
steps of docs/contributing.md, "Adding a method", with the exact method's modules as its
RTL and models, and its two registry records) is picked up, with nothing else edited, by
the CLI (``bumprtl emit rotation|illumination --method toy``, its help, the golden
bench's ``--methods`` choices), the reports and renders (Table 1's columns, the FPGA
report's rows, the float64 models, the formal targets) and the method-parametrized tests
(their collected ids). Each check runs in a fresh interpreter that imports the toy first,
as an edit to the registry files would be seen."""

import subprocess
import sys

from tests.conftest import ROOT

TOY = "tests.tools.toy_method"

# The suites that run every method (or every per-pixel method) of the registry.
GENERIC_TESTS = ["tests/rtl/test_methods.py", "tests/rtl/test_rotation.py",
                 "tests/sim/tb/test_tb_datapath.py", "tests/rtl/test_pipeline.py",
                 "tests/sim/golden/float/test_models.py"]

CHECK = f"""
import io, contextlib, json, sys
from pathlib import Path
import {TOY}
from bumprtl.gen.cli.main import build_parser, main
from bumprtl.gen.report.table1 import TABLE1_ORDER
from bumprtl.gen.report.fpga import fpga_units
from bumprtl.rtl.config import Config
from bumprtl.rtl.sidecar import load
from bumprtl.sim.formal.targets import TARGETS
from bumprtl.sim.golden.float.models import FLOAT_MODELS
out = Path(sys.argv[1])
found = {{}}
for unit in ("rotation", "illumination"):
    with contextlib.redirect_stdout(io.StringIO()):
        found[f"emit {{unit}}"] = main(["emit", unit, "--method", "toy", "--angle-bits", "8",
                                       "--frac-bits", "8", "--out", str(out)]) == 0
    found[f"sidecar {{unit}}"] = load((out / f"bumprtl_{{unit}}.json")
                                      if (out / f"bumprtl_{{unit}}.json").exists() else
                                      (out / f"{{unit}}.json")).method == "toy"
help_text = io.StringIO()
with contextlib.redirect_stdout(help_text):
    try:
        main(["emit", "--help"])
    except SystemExit:
        pass
found["emit --help"] = "toy" in help_text.getvalue()
golden = build_parser().parse_args(["bench", "golden", "--methods", "toy"])
found["bench golden --methods"] = golden.methods == ["toy"]
found["table1 column"] = "toy" in TABLE1_ORDER
found["fpga rows"] = any(design == "toy" for _, design, _ in fpga_units(Config()))
found["float64 models"] = "toy" in FLOAT_MODELS
found["formal targets"] = "rotation_toy" in TARGETS and "illumination_toy" in TARGETS
print(json.dumps(found))
"""


def _run(argv):
    return subprocess.run([sys.executable, *argv], cwd=ROOT, capture_output=True, text=True,
                          timeout=600)


def test_the_cli_reports_and_targets_pick_up_a_toy_method(build_dir):
    run = _run(["-c", CHECK, str(build_dir)])
    assert run.returncode == 0, run.stderr[-3000:]
    found = __import__("json").loads(run.stdout.strip().splitlines()[-1])
    missed = [k for k, v in found.items() if not v]
    assert not missed, f"not picked up from the registry: {missed}"
    assert len(found) == 10


def test_the_method_parametrized_tests_pick_up_a_toy_method():
    """Collected with the toy registered, every generic suite has toy cases; collected
    without it, none (so the check is not satisfied by a name that is always there)."""
    with_toy = _run(["-m", "pytest", "-p", TOY, "--collect-only", "-q", "-p", "no:cacheprovider",
                     *GENERIC_TESTS])
    assert with_toy.returncode == 0, with_toy.stdout[-3000:] + with_toy.stderr[-3000:]
    ids = with_toy.stdout.splitlines()
    for path in GENERIC_TESTS:
        assert any(i.startswith(path) and "toy" in i for i in ids), f"{path}: no toy case"
    without = _run(["-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
                    GENERIC_TESTS[0]])
    assert without.returncode == 0 and not any("toy" in i for i in without.stdout.splitlines())
