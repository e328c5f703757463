"""``bumprtl board``'s command (gen/cli/board.py) with the bitstream flow, the part costs and
the frame simulation stood in (make board runs them): the seeds it passes and the minimum
Fmax over them with the constraint met or not, the files it names, the summary it writes,
the exit status when a frame differs, and its refusals of --seeds and --check-frames in
one line, exit 2, nothing written."""

import json

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.cli import board as cli_board

SMALL = ["--texture-size", "16"]
_CHECKED = {}


@pytest.fixture(autouse=True)
def checked_once(monkeypatch):
    """check_board's real verdict (tests/board/test_board.py tests it), computed once per
    board, mode and scene: its block-RAM count builds the pipeline (half a second)."""
    real = cli_board.check_board

    def once(board, mode, scene, *memory):
        key = (board, mode, scene, *memory)
        if key not in _CHECKED:
            _CHECKED[key] = real(board, mode, scene, *memory)
        return _CHECKED[key]
    monkeypatch.setattr(cli_board, "check_board", once)


def _build(fmax_by_seed):
    calls = []

    def build(scene, mode, out, board, seeds, pipe_hz=None, memory=None):
        assert memory is None                   # a map in block RAM has no SDRAM parts
        calls.append((scene.name, mode.name, out, board, list(seeds)) + ((pipe_hz,) if pipe_hz else ()))
        return [{"seed": s, "seconds": 12.0,
                 "resources": {"LUT4": (100 * s, 83640), "DSP": (4, 156)},
                 "fmax": fmax_by_seed[s]} for s in seeds]
    return build, calls


def _no(*args, **kw):
    raise AssertionError("not to be called here")


def test_bitstream_seeds_minimum_fmax_parts_and_summary(tmp_path, monkeypatch, run_cli):
    build, calls = _build({2: {"sync (pixel)": (30.0, 25.2), "shift": (130.0, 126.0)},
                           3: {"sync (pixel)": (27.5, 25.2), "shift": (120.0, 126.0)}})
    monkeypatch.setattr(cli_board, "build_bitstream", build)
    monkeypatch.setattr(cli_board, "part_costs", lambda scene, mode, work, memory=None: {
        "pipeline": {"LUT4": 10, "DSP": 4}, "buffer": {"LUT4": 1, "DSP": 0}})
    monkeypatch.setattr(cli_board, "check_frames", _no)
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", *SMALL, "--out", out, "--seeds", "2,3", "--parts"])
    assert r.returncode == 0, r.stderr
    assert calls == [("default", "640x480", out, "ulx3s", [2, 3])]
    lines = r.stdout.splitlines()
    assert lines[0].startswith("seed 2: LUT4 200/83640, DSP 4/156; Fmax shift 130.0 MHz "
                               "(constraint 126.0), sync (pixel) 30.0 MHz (constraint 25.2); 12 s")
    assert f"wrote {out / 'ulx3s_85f.bit'}" in lines and f"wrote {out / 'ulx3s_85f.svf'}" in lines
    # the minimum over the seeds, per clock, against its constraint
    assert "shift: minimum Fmax over seeds 2,3: 120.0 MHz, constraint 126.0 MHz: NOT MET" in lines
    assert "sync (pixel): minimum Fmax over seeds 2,3: 27.5 MHz, constraint 25.2 MHz: met" in lines
    assert "pipeline: LUT4 10, DSP 4" in lines and "buffer: LUT4 1, DSP 0" in lines
    summary = json.loads((out / "summary_640x480.json").read_text())
    assert (summary["board"], summary["device"], summary["mode"]) == ("ulx3s", "LFE5U-85F", "640x480")
    assert summary["fmax_min"] == {"sync (pixel)": [27.5, 25.2], "shift": [120.0, 126.0]}
    assert [b["seed"] for b in summary["builds"]] == [2, 3] and "pipeline" in summary["parts"]


def _frames(same, timing_errors=(), underflow=0, order_error=0):
    seen = {}

    def check(scene, mode, out, frames, data, pipe_hz=None, memory=None):
        seen.update(mode=mode.name, out=out, frames=frames, words=len(data[0]), pipe_hz=pipe_hz,
                    memory=memory)
        captured = [np.full((mode.v_active, mode.h_active, 3), 40 + k, np.uint8)
                    for k in range(frames)]
        return {"captured": captured, "same": list(same), "timing_errors": list(timing_errors),
                "underflow": underflow, "order_error": order_error, "build_s": 1.0, "run_s": 2.0,
                "first": 0 if memory is None else 1}
    return check, seen


@pytest.mark.parametrize("same, errors, underflow, status", [
    ([True, True], [], 0, 0),
    ([True, False], [], 0, 1),
    ([True, True], ["hsync 9 cycles, want 8"], 0, 1),
    ([True, True], [], 3, 1),
])
def test_test_mode_checks_frames_without_a_bitstream(same, errors, underflow, status, tmp_path,
                                                     monkeypatch, run_cli):
    check, seen = _frames(same, errors, underflow)
    monkeypatch.setattr(cli_board, "check_frames", check)
    monkeypatch.setattr(cli_board, "build_bitstream", _no)
    monkeypatch.setattr(cli_board, "part_costs", _no)
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", *SMALL, "--mode", "test", "--out", out, "--check-frames", "2",
                 "--parts"])
    assert r.returncode == status, r.stderr
    assert seen["mode"] == "test" and seen["frames"] == 2 and seen["out"] == out / "sim_test"
    assert "frame 0 (light step 0): identical to the golden frame" in r.stdout
    verdict = "identical to the golden frame" if same[1] else "DIFFERS from the golden frame"
    assert f"frame 1 (light step 1): {verdict}" in r.stdout
    assert ("sync/blanking: WRONG" in r.stdout) == bool(errors)
    for e in errors:
        assert f"timing: {e}" in r.stdout
    assert f"underflow {underflow}, order error 0" in r.stdout
    png = out / "frame0_test.png"
    assert f"wrote {png}" in r.stdout
    assert np.array_equal(np.asarray(Image.open(png)), np.full((24, 32, 3), 40, np.uint8))
    summary = json.loads((out / "summary_test.json").read_text())
    assert summary["frames"]["same"] == same and "builds" not in summary


def test_no_bitstream_and_no_frames_writes_the_summary_only(tmp_path, monkeypatch, run_cli):
    for name in ("build_bitstream", "part_costs", "check_frames"):
        monkeypatch.setattr(cli_board, name, _no)
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", *SMALL, "--out", out, "--no-bitstream"])
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["summary_640x480.json"]
    assert json.loads((out / "summary_640x480.json").read_text())["scene"] == "default"


@pytest.mark.parametrize("flags, message", [
    (["--seeds", "0"], "--seeds must be a comma-separated list of positive integers, got '0'"),
    (["--seeds", "1,x"], "got '1,x'"),
    (["--seeds", ""], "got ''"),
    (["--seeds", "2,-1"], "got '2,-1'"),
    (["--check-frames", "-1"], "--check-frames must be >= 0, got -1"),
])
def test_bad_seeds_or_frames_one_line_exit_2_nothing_written(flags, message, board_refusal):
    assert message in board_refusal([*SMALL, *flags])


def test_pipe_mhz_reaches_the_bitstream_and_the_frames_and_is_refused_below_the_pixel_clock(
        tmp_path, monkeypatch, run_cli):
    build, calls = _build({1: {"sync (pixel)": (30.0, 25.2)}})
    check, seen = _frames([True])
    monkeypatch.setattr(cli_board, "build_bitstream", build)
    monkeypatch.setattr(cli_board, "check_frames", check)
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", *SMALL, "--out", out, "--pipe-mhz", "60", "--check-frames", "1"])
    assert r.returncode == 0, r.stderr
    assert calls == [("default", "640x480", out, "ulx3s", [1], 60e6)] and seen["pipe_hz"] == 60e6
    assert json.loads((out / "summary_640x480.json").read_text())["pipe_mhz"] == 60.0
    bad = tmp_path / "bad"
    r = run_cli(["board", "ulx3s", *SMALL, "--out", bad, "--pipe-mhz", "20", "--no-bitstream"])
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "pipe clock must be at least the pixel clock" in r.stderr and "got 20 MHz" in r.stderr
    assert not bad.exists()


@pytest.mark.parametrize("value, message", [
    ("inf", "--pipe-mhz must be a finite clock rate, got inf"),
    ("nan", "--pipe-mhz must be a finite clock rate, got nan"),
    ("60", "--pipe-mhz has no effect without a bitstream or --check-frames"),
])
def test_pipe_mhz_without_meaning_is_refused(value, message, board_refusal):
    assert board_refusal([*SMALL, "--mode", "test", "--pipe-mhz", value]) == f"bumprtl: error: {message}"


def test_pipe_mhz_without_a_bitstream_reaches_the_frame_check(tmp_path, monkeypatch, run_cli):
    """In the test mode (no bitstream) --pipe-mhz has an effect through --check-frames: the
    frames are simulated with the pipeline at that clock, and nothing is built."""
    check, seen = _frames([True])
    for name in ("build_bitstream", "part_costs"):
        monkeypatch.setattr(cli_board, name, _no)
    monkeypatch.setattr(cli_board, "check_frames", check)
    out = tmp_path / "b"
    r = run_cli(["board", "ulx3s", *SMALL, "--mode", "test", "--out", out, "--pipe-mhz", "40",
                 "--check-frames", "1"])
    assert r.returncode == 0, r.stderr
    assert seen["mode"] == "test" and seen["frames"] == 1 and seen["pipe_hz"] == 40e6
    assert json.loads((out / "summary_test.json").read_text())["pipe_mhz"] == 40.0
