"""``bumprtl recommend --max-error-lsb E [--device D]``: the cheapest configuration whose
measured colour error (eq. 2's output, what a pixel shows; gen/bench/sweep.error_lsb) meets
the bound, from the sweep data (``bumprtl bench sweep``), with the
evidence: its error sets, its cost, its speed, the runners-up and the command that made
the numbers. Nothing is re-measured or estimated here. Without ``--sweep`` and without a local
sweep (``build/bench/sweep.json``), it reads the sweep that ships in ``docs/data/sweep.json``
(the one docs/bench.md shows) and says so.

It names the maps its evidence covers (each map's size and number of distinct normals, as
the sweep recorded them), and does not count a palette point that quantized on none of the
maps: a palette holding every distinct normal of the maps measured stores them exactly, so
its error there says nothing about a larger map, where the palette must quantize. A palette
point that held every normal of some maps is counted on the others, and says which.
"""

import json
from pathlib import Path

from bumprtl.gen.bench.sweep import (
    cost_key,
    describe_map,
    error_lsb,
    maps_of,
    measured_maps,
    ok_points,
    point_label,
    unquantized_maps,
)
from bumprtl.rtl.config import BumpError

__all__ = ["recommend", "rank_key", "recommend_report", "LOCAL_SWEEP", "SHIPPED_SWEEP", "sweep_path", "not_evidence",
           "evidence_line"]

LOCAL_SWEEP = Path("build/bench/sweep.json")          # what `bumprtl bench sweep` writes
# The sweep docs/bench.md was made from, in the checkout (gen/report/ -> the repository root).
SHIPPED_SWEEP = Path(__file__).resolve().parents[2] / "docs" / "data" / "sweep.json"


def sweep_path(given=None):
    """``(path, note)``: ``given``, else the local sweep, else the shipped one (the note
    says which and why)."""
    if given is not None:
        return Path(given), None
    if LOCAL_SWEEP.is_file():
        return LOCAL_SWEEP, None
    if SHIPPED_SWEEP.is_file():
        return SHIPPED_SWEEP, (f"no local sweep ({LOCAL_SWEEP}): reading the sweep that ships "
                               f"with bumprtl, {SHIPPED_SWEEP} (run `bumprtl bench sweep` to "
                               f"measure your own)")
    return LOCAL_SWEEP, None


def _load(path):
    path = Path(path)
    if not path.is_file():
        raise BumpError(f"sweep data {path} does not exist: run `bumprtl bench sweep` first "
                        f"(or pass --sweep FILE)")
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise BumpError(f"sweep data {path} is not valid JSON ({e})") from None
    if not isinstance(data, dict) or not isinstance(data.get("points"), list):
        raise BumpError(f"sweep data {path} has no 'points' list: not a `bumprtl bench sweep` output")
    return data


def _fits(point, device):
    f = point["cost"].get("fpga")
    if not f or f.get("device") != device:
        return False
    avail = f.get("available") or {}
    return all(avail.get(k) is None or f[k] <= avail[k] for k in ("LUT4", "DSP", "BRAM"))


def not_evidence(data):
    """The palette points that quantized on none of the maps they were measured on (they held
    every distinct normal of each): ``recommend`` does not count them."""
    return [p for p in ok_points(data) if p["method"] == "palette" and measured_maps(p)
            and len(unquantized_maps(p, data)) == len(measured_maps(p))]


def evidence_line(data):
    """``evidence: maps bricks (512², 262104 distinct normals), ...``: what the sweep's
    scene errors cover."""
    maps = maps_of(data)
    if not maps:
        return "evidence: no maps recorded in this sweep (random and adversarial vectors only)"
    return "evidence: maps " + ", ".join(describe_map(m) for m in maps)


def rank_key(point, device=None):
    """The order of :func:`recommend`'s candidates: cheapest first by :func:`cost_key`; equal
    cost, the smaller worst colour error (:func:`error_lsb`); equal again, the narrower
    configuration (angle_bits, then frac_bits, then palette_size), then the method name.
    A total order on distinct configurations, so the answer never depends on the order of
    the sweep's points."""
    c = point.get("config", {})
    width = lambda k: point.get(k, c.get(k, 0)) or 0
    return (cost_key(point, device), error_lsb(point), width("angle_bits"), width("frac_bits"),
            width("palette_size"), point["method"])


def recommend(data, max_error_lsb, device=None):
    """``(best, candidates)``: the points meeting the bound (and fitting ``device``) in
    :func:`rank_key`'s order (cheapest first; ties by error, then the narrower widths, then
    the method name); raises BumpError when none does. A palette point in
    :func:`not_evidence` is never a candidate."""
    if isinstance(max_error_lsb, bool) or not isinstance(max_error_lsb, (int, float)) or max_error_lsb < 0:
        raise BumpError(f"max_error_lsb must be a number >= 0, got {max_error_lsb!r}")
    skipped = {id(p) for p in not_evidence(data)}
    points = [p for p in ok_points(data) if error_lsb(p) is not None and id(p) not in skipped]
    if device:
        placed = [p for p in points if p["cost"].get("fpga", {}).get("device") == device]
        if not placed:
            raise BumpError(f"the sweep has no FPGA numbers for device {device}: run "
                            f"`bumprtl bench sweep --fpga --device {device}` first")
        points = [p for p in placed if _fits(p, device)]
    meeting = sorted((p for p in points if error_lsb(p) <= max_error_lsb),
                     key=lambda p: rank_key(p, device))
    if not meeting:
        best = min((error_lsb(p) for p in points), default=None)
        raise BumpError(f"no configuration in the sweep meets max_error_lsb = {max_error_lsb}"
                        f"{' on ' + device if device else ''}: the smallest measured error is "
                        f"{best} LSB (allowed bounds: >= {best})"
                        + (f"; not counted, no quantization on the maps measured: "
                           f"{', '.join(point_label(p) for p in not_evidence(data))}" if skipped else ""))
    return meeting[0], meeting


def _evidence(p):
    err, cost, speed = p["error"], p["cost"], p["speed"]
    lines = [f"  error (8-bit LSB vs float64): worst colour {error_lsb(p)}"]
    for channel, sets in (err.get("channels") or {"diffuse": err}).items():
        for k in ("random", "adversarial"):
            if k in sets:
                lines.append(f"    {channel} {k}: max {sets[k]['max']}, mean {sets[k]['mean']} "
                             f"over {sets[k]['n']} vectors")
    for name, s in err.get("scenes", {}).items():
        if "max_lsb" in s:
            psnr = "inf (identical)" if s["psnr_db"] is None else f"{s['psnr_db']} dB"
            lines.append(f"    scene {name}: PSNR {psnr}, max {s['max_lsb']}")
    lines.append(f"  cost: {cost['multipliers']} multipliers, {cost['adders']} adders, "
                 f"{cost['table_bits']} ROM bits, {cost['ram_bits']} RAM bits")
    if "fpga" in cost:
        f = cost["fpga"]
        lines.append(f"    {f['device']}: {f['LUT4']} LUT4, {f['DSP']} DSP, {f['BRAM']} BRAM, "
                     f"Fmax {f['fmax_mhz']} MHz")
    lines.append("  speed: " + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                                     for k, v in speed.items() if not k.endswith("note")))
    return lines


def _flags(p):
    c = p["config"]
    if p["method"] == "palette":
        return f"--palette-size {c['palette_size']}"
    return f"--method {c['method']} --angle-bits {c['angle_bits']} --frac-bits {c['frac_bits']}"


def recommend_report(max_error_lsb, device=None, sweep=None):
    """``bumprtl recommend``: prints the cheapest configuration of the sweep JSON ``sweep``
    (default: :func:`sweep_path`'s) whose worst measured colour error is at most
    ``max_error_lsb``, ranked by ECP5 cost on ``device`` when given, with the evidence;
    returns 0 (none meets the bound: BumpError)."""
    path, note = sweep_path(sweep)
    if note:
        print(note + "\n")
    sweep = path
    data = _load(path)
    best, meeting = recommend(data, max_error_lsb, device)
    order = ("DSP, block RAM, LUT4 on " + device if device else
             "multipliers + dividers + square roots, then ROM+RAM bits, then adders")
    print(f"cheapest configuration with worst measured colour error <= {max_error_lsb} LSB "
          f"(cheapest by {order}):\n")
    print(f"  {point_label(best)}: {_flags(best)}")
    print("\n".join(_evidence(best)))
    exact = unquantized_maps(best, data)
    if exact:
        print(f"  note: this palette held every distinct normal of {', '.join(exact)} (no "
              f"quantization there); its error comes from "
              f"{', '.join(k for k in measured_maps(best) if k not in exact)}")
    if len(meeting) > 1:
        print("\nnext cheapest meeting the bound:")
        for p in meeting[1:4]:
            print(f"  {point_label(p)}: error {error_lsb(p)}, cost key {cost_key(p, device)}")
    print("\n" + evidence_line(data))
    for p in not_evidence(data):
        print(f"not counted: {point_label(p)} held every distinct normal of the maps measured "
              f"(no quantization happened: not evidence for a larger map)")
    print(f"evidence from {sweep}, made by `{data.get('command', 'bumprtl bench sweep')}`")
    return 0
