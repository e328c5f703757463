"""`report fpga --scene-seeds` places the rows the 200 MHz goal is about (every scene
pipeline and the default method's pipeline) at its seeds, every other row at --seeds."""

from bumprtl.gen.report.fpga import FpgaRun, _row_seeds, fpga_units
from bumprtl.rtl.config import Config


def test_scene_seeds_reach_the_scene_rows_and_the_default_pipeline_only():
    run = FpgaRun(seeds=(1,), scene_seeds=(1, 2, 3))
    seeds = {label: _row_seeds(run, unit) for unit in fpga_units(Config())
             for label in [unit[0]]}
    many = {label for label, s in seeds.items() if s == [1, 2, 3]}
    assert many == {label for label in seeds if label.startswith("scene_")} | {"exact_pipeline"}
    assert {"exact_setup", "exact_illumination", "lee_pipeline", "peercy_pipeline"} <= {
        label for label, s in seeds.items() if s == [1]}


def test_without_scene_seeds_every_row_takes_seeds():
    run = FpgaRun(seeds=(2, 5))
    assert {tuple(_row_seeds(run, u)) for u in fpga_units(Config())} == {(2, 5)}
