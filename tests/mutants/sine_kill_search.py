"""Search pixels on which a sine-ROM data-register mutant changes a pipeline output.

The mutant flips bit ``flip`` of one quarter-wave ROM word read when its bit ``ctrl`` is set
(``mutate -mode cnot1 ... -port A -portbit flip -ctrlbit ctrl`` on the reset mux in front
of the ROM's data register; with no stall the register loads each word once). The golden
model with that read patched is compared with the plain one on random pixels of the scene.

python tests/mutants/sine_kill_search.py two-lights l_cy 3 5 20000   (writes kill_<scene>_<read>.npz here)
python tests/mutants/sine_kill_search.py full n_c2 0 2 200000
"""
import sys, time
import numpy as np
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.gen.render.rtl import scene_stimulus, scene_texels
from bumprtl.sim.tb.bulk_frame import coverage_frame
from bumprtl.sim.golden.fixed import pipeline as gp
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed, random_inputs
from bumprtl.rtl.tables import cos_lookup

name, read, flip, ctrl, n = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
scene = load_scene_config(name)
cfg = scene.config
_, words, _, table, base = scene_stimulus(scene, 16)
texels = scene_texels(scene, base)
frame = coverage_frame(scene, words, texels)


def mut(v):
    m = np.abs(v)
    m2 = m ^ (((m >> ctrl) & 1) << flip)
    return np.sign(v) * m2


orig = gp.rotation_fixed
calls = []


def patched(codes, c):
    out = dict(orig(codes, c))
    k = len(calls)
    calls.append(1)
    if read == "l_cy" and k == 0:              # light 0's L: 2y = c(Y) - c(X), Y = th - D
        th, d = codes["l.theta"], codes["l.phi"] - codes["n.phi"]
        y = th - d
        out["l.y2"] = out["l.y2"] - cos_lookup(c, y) + mut(cos_lookup(c, y))
    if read == "n_c2":                         # n.z4 = -(c(a-t) - ...) + ...: every light's
        a = codes["b.theta"] + codes["b.phi"]
        t = codes["n.theta"]
        out["n.z4"] = out["n.z4"] + cos_lookup(c, a - t) - mut(cos_lookup(c, a - t))
    return out


rng = np.random.default_rng(28)
t0 = time.process_time()
inputs = random_inputs(scene, n, rng)
inputs = {k: np.asarray(v, np.int64) for k, v in inputs.items()}
gold = pipeline_fixed(inputs, scene, frame.words, frame.polygon, frame.texels)
gp.rotation_fixed = patched
calls.clear()
mutant = pipeline_fixed(inputs, scene, frame.words, frame.polygon, frame.texels)
gp.rotation_fixed = orig
diff = np.zeros(n, bool)
for k in gold:
    dk = np.asarray(gold[k]) != np.asarray(mutant[k])
    if dk.any():
        print(f"{k}: {int(dk.sum())} of {n} pixels differ")
    diff |= dk
idx = np.nonzero(diff)[0]
print(f"{len(idx)} of {n} random pixels differ ({time.process_time() - t0:.1f} s CPU); first:")
for i in idx[:8]:
    print("  ", {k: int(v[i]) for k, v in inputs.items()},
          {k: (int(gold[k][i]), int(mutant[k][i])) for k in gold if gold[k][i] != mutant[k][i]})
np.savez(f"kill_{name}_{read}.npz", **{k: v[idx] for k, v in inputs.items()})
