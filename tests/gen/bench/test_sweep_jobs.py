"""bench sweep --fpga places as jobs of gen/tools/jobs.py after the points (make fpga; in-process local
cluster here, the tools faked): the point gets its row and hardware speed, a failed
placement its fpga_error, and a second run reads the cache without a job."""

import json
from types import SimpleNamespace

import pytest

from bumprtl.gen.bench import sweep as bench_sweep
from bumprtl.gen.flow import fpga
from bumprtl.gen.tools import jobs
from bumprtl.rtl.config import Config


@pytest.mark.fpga
def test_sweep_places_its_points_as_jobs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                   # the shared cache build/fpga_cache is here
    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)
    calls = []

    def fake(v_path, top, device, work, lpf=fpga.LPF, seed=1):
        calls.append(top)
        if "lee" in top:
            raise fpga.FpgaError("nextpnr-ecp5 failed (status 1): ERROR: no room")
        (work / f"{top}.pnr.json").write_text(json.dumps({"utilization": {}}))
        return {"unit": top, "fmax_mhz": 123.0}

    monkeypatch.setattr(fpga, "place_and_route", fake)
    opts = SimpleNamespace(fpga=True, device="LFE5U-25F", scheduler=None, jobs=2)

    def points():
        """Three palette points: two of the same hardware (sN 16, labels palette and
        same), one of another (sN 32, label lee: its placement fails)."""
        ctx = SimpleNamespace(pending=[])
        pts = [{"method": m, "cost": {}, "speed": {}} for m in ("palette", "same", "lee")]
        for p, size in zip(pts, (16, 16, 32), strict=False):
            bench_sweep._hardware(p, Config(palette_size=size), bench_sweep._palette_unit,
                                  "palette", ctx, opts)
        bench_sweep.place_pending(ctx, opts, progress=False)
        return pts

    first = points()
    assert sorted(calls) == ["lee_palette", "palette_palette"]       # one job per hardware
    for p in first[:2]:
        assert p["cost"]["fpga"]["fmax_mhz"] == 123.0 and p["speed"]["hw_pix_s"] == 123e6
    assert first[1]["cost"]["fpga"]["unit"] == "same_palette"
    assert first[2]["cost"]["fpga_error"] == "nextpnr-ecp5 failed (status 1): ERROR: no room"
    again = points()
    assert again[:2] == first[:2] and len(calls) == 3                # only the failed one again
