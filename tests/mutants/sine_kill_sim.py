"""Stream pixels found by tests/mutants/sine_kill_search.py through the saved mutated netlist on Icarus
(tests/mutants/netlist.py's run_one: the bulk path, four traffic patterns, golden compare),
mutsel = 0 (must pass) and mutsel = the mutant.

run in the directory of the search's kill_*.npz:
python tests/mutants/sine_kill_sim.py two-lights l_cy 1 K  |  ... full n_c2 6 K
"""
import dataclasses, json, sys, time
from pathlib import Path
import numpy as np
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "mutants"))
from netlist import run_one
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.gen.render.rtl import scene_stimulus, scene_texels
from bumprtl.sim.tb.bulk_frame import coverage_frame
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed

name, read, mut, k = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
scene = load_scene_config(name)
_, words, _, table, base = scene_stimulus(scene, 16)
texels = scene_texels(scene, base)
frame = coverage_frame(scene, words, texels)
found = np.load(f"kill_{name}_{read}.npz")
inputs = {key: np.asarray(found[key][:k], np.int64) for key in found.files}
golden = pipeline_fixed(inputs, scene, frame.words, frame.polygon, frame.texels)
golden = {key: np.asarray(v, np.int64) for key, v in golden.items()}
golden["tag"] = inputs["tag"]
fr = dataclasses.replace(frame, inputs=inputs, golden=golden)
rtl = ROOT / f"build/netlist_mutants/scene_{name}/pipeline_{name}/rtl"     # the saved run
meta = json.loads((rtl / "pipeline.json").read_text())
job = {"inputs": fr.inputs, "expected": fr.expected(meta), "setup": fr.setup(meta)}
for idx in (0, mut):
    t0, c0 = time.time(), time.process_time()
    r = run_one(rtl / "mutated.v", rtl / "pipeline.json", job, Path.cwd() / f"sim_{name}_{idx}", idx, "icarus")
    print(f"{name} mutsel={idx}, {k} pixels x 4 patterns: {r} ({time.time() - t0:.0f} s wall)", flush=True)
