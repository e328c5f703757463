"""How the job layer scales: one command run cold with 1 worker, then with 2, side by side.

    python tests/tools/scale.py fpga --workers 1,2 --angle-bits 10 --frac-bits 11 \\
        --unit exact_setup --unit scene_palette ...
    python tests/tools/scale.py formal --workers 1,2 sincos pipeline_palette ...

Each run is a fresh ``bumprtl report fpga`` (or ``bumprtl formal``) in its own directory
under ``--out`` (default build/scale), so nothing is cached and each keeps its job logs
(``<run>/build/jobs/*.log``). Prints, per worker count: the wall time, the number of jobs,
the sum of the jobs' times, the longest job; then the ratio of the first two walls and the
projection for more workers: ``overhead + max(longest job, sum / N)`` (the client's own
time and the cluster start-up are the wall time not covered by jobs at 1 worker; with N
workers no schedule beats the longest job or the sum spread evenly). Writes
``<out>/scale.json``.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

BUMPRTL = Path(sys.executable).parent / "bumprtl"


def job_seconds(log_dir):
    """{job name: seconds} from the job logs' ``seconds`` lines."""
    out = {}
    for path in sorted(Path(log_dir).glob("*.log")):
        m = re.search(r"^seconds ([0-9.]+)$", path.read_text(errors="replace"), re.M)
        if m:
            out[path.stem] = float(m.group(1))
    return out


def one_run(kind, workers, rest, root):
    """Run the command cold in ``root`` with ``workers`` local workers; the measurements."""
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    if kind == "fpga":
        argv = [str(BUMPRTL), "report", "fpga", "--jobs", str(workers), "--out",
                str(root / "report.md"), "--work", str(root / "fpga_cache"), "--samples", "1000", *rest]
    else:
        argv = [str(BUMPRTL), "formal", "-j", str(workers), "--out", str(root / "formal"),
                "--no-mutants", *rest]
    env = {**os.environ, "BUMPRTL_PROGRESS": "0"}
    env.pop("BUMPRTL_SCHEDULER", None)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=root, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    (root / "stdout.txt").write_text(proc.stdout + proc.stderr)
    if proc.returncode not in (0, 1):
        sys.exit(f"{' '.join(argv)} failed with status {proc.returncode}: see {root}/stdout.txt")
    jobs = job_seconds(root / "build" / "jobs")
    return {"workers": workers, "wall_s": round(wall, 1), "jobs": len(jobs),
            "job_sum_s": round(sum(jobs.values()), 1),
            "longest_job": max(jobs, key=jobs.get) if jobs else None,
            "longest_job_s": round(max(jobs.values()), 1) if jobs else 0.0,
            "job_s": jobs, "command": " ".join(argv[1:])}


def project(run, n):
    """Wall time with ``n`` workers from a 1-worker run (see the module doc)."""
    overhead = max(0.0, run["wall_s"] - run["job_sum_s"])
    return round(overhead + max(run["longest_job_s"], run["job_sum_s"] / n), 1)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("kind", choices=("fpga", "formal"))
    p.add_argument("--workers", default="1,2", help="worker counts, comma-separated (default 1,2)")
    p.add_argument("--out", type=Path, default=Path("build/scale"))
    p.add_argument("--project", default="8,32,128", help="worker counts to project (default 8,32,128)")
    a, rest = p.parse_known_args(argv)
    try:
        counts = [int(w) for w in a.workers.split(",")]
        projected = [int(w) for w in a.project.split(",")]
    except ValueError:
        p.error(f"--workers and --project must be comma-separated integers, got {a.workers!r}, {a.project!r}")
    load = os.getloadavg()
    runs = []
    for w in counts:
        run = one_run(a.kind, w, rest, (a.out / f"{a.kind}_{w}w").resolve())
        runs.append(run)
        print(f"{w} worker(s): wall {run['wall_s']} s, {run['jobs']} jobs, job sum "
              f"{run['job_sum_s']} s, longest {run['longest_job']} {run['longest_job_s']} s", flush=True)
    base = runs[0]
    result = {"kind": a.kind, "argv": sys.argv[1:], "runs": runs,
              "load_before": load, "load_after": os.getloadavg(),
              "projection": {n: project(base, n) for n in projected}}
    if len(runs) > 1:
        result["ratio"] = round(runs[0]["wall_s"] / runs[1]["wall_s"], 2)
        print(f"wall ratio {runs[0]['workers']} / {runs[1]['workers']} workers: {result['ratio']}")
    print("projection from the 1-worker run: " + ", ".join(
        f"{n} workers {s} s" for n, s in result["projection"].items()))
    print(f"load average at the end: {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / f"scale_{a.kind}.json").write_text(json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
