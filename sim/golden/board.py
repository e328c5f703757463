"""The board's inputs and frames as numbers (docs/board.md): the data the board top is built
with (the plane's normal, the light table) and the golden frame the board must show.

The board (rtl/board.py) renders a plane facing the viewer, N = (0, -1, 0) in the world
frame of bumprtl.sim.scenes, under directional lights at LIGHT_ELEVATION degrees that turn
about the viewing axis by 360 / steps degrees a frame; light j sits LIGHT_AZIMUTH_STEP * j
degrees further round (as in ``bumprtl render``). H is the half vector with the viewer
V = (0, -1, 0). The hardware reads L and H of every light from a table of ``steps``
entries made by :func:`light_table`; the per-pixel texel coordinates are
``rtl.board.texel_coords`` of the screen position, the very function the hardware
elaborates. :func:`frame_inputs` makes frame f's payload arrays with both;
:func:`golden_frame` runs them through the bit-exact pipeline model.

A scene whose surface (:func:`surface`) is a sphere is shown as a turning globe instead:
N and (u, v) of every pixel come from the globe unit's bit-exact model
(sim/golden/globe.globe_fixed) of ``rtl.board.globe_offsets`` of the screen position, at
the rotation ``rtl.board.globe_rotation`` of the frame; the normal is in the same world frame
as the lights, so the light table is the plane's. Pixels outside the globe are black.
"""

import numpy as np

from bumprtl.rtl.board import globe_config, globe_offsets, globe_rotation, texel_coords
from bumprtl.rtl.layouts import light_keys
from bumprtl.sim.golden.common import cartesian_to_polar
from bumprtl.sim.golden.fixed.common import angle_codes
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.golden.globe import globe_fixed
from bumprtl.sim.scenes import SCENES, light_direction

__all__ = ["LIGHT_ELEVATION", "LIGHT_AZIMUTH", "LIGHT_AZIMUTH_STEP", "STEPS", "VIEW",
           "surface", "plane_constants", "light_table", "frame_inputs", "golden_frame"]

LIGHT_ELEVATION = 45.0
LIGHT_AZIMUTH = 30.0          # light 0 in frame 0
LIGHT_AZIMUTH_STEP = 120.0
STEPS = 256                   # light steps a turn (one a frame)
VIEW = np.array([0.0, -1.0, 0.0])
PLANE_NORMAL = np.array([0.0, -1.0, 0.0])


def _codes(vec, cfg):
    phi, theta = cartesian_to_polar(vec)
    return int(angle_codes(phi, cfg)), int(angle_codes(theta, cfg))


def surface(scene):
    """The surface the board shows for ``scene`` (a SceneConfig): its ``geometry``, else its
    image's own (sim/scenes.SCENES), a user's map on a plane."""
    return scene.geometry or (SCENES[scene.image][1] if scene.image else "plane")


def plane_constants(scene):
    """{payload key: code} of the fields that never change: the plane's normal N."""
    phi, theta = _codes(PLANE_NORMAL, scene.config)
    return {"n.phi": phi, "n.theta": theta}


def light_table(scene, steps=STEPS):
    """One {payload key: code} per light step: L (and H with specular) of every light."""
    cfg, table = scene.config, []
    for s in range(steps):
        entry = {}
        for j, keys in enumerate(light_keys(cfg)):
            az = (LIGHT_AZIMUTH + 360.0 * s / steps + LIGHT_AZIMUTH_STEP * j) % 360.0
            l = light_direction(LIGHT_ELEVATION, az)
            h = (l + VIEW) / np.linalg.norm(l + VIEW)
            vec = {"l": l, "h": h}
            for own, key in keys.items():
                phi, theta = _codes(vec[own[0]], cfg)
                entry[key] = phi if own.endswith("phi") else theta
        table.append(entry)
    return table


def frame_inputs(scene, mode, frame, table):
    """The pipeline's input arrays (raster order) of frame ``frame`` (light step
    ``frame % len(table)``), made by the formulas the hardware source uses; a globe's
    (:func:`surface` ``sphere``) carry ``inside`` in the tag's top bit."""
    y, x = np.mgrid[0:mode.v_active, 0:mode.h_active]
    x, y = x.ravel().astype(np.int64), y.ravel().astype(np.int64)
    n = mode.pixels
    count = np.arange(n, dtype=np.int64) + frame * n
    if surface(scene) == "sphere":
        hw = scene.hardware
        gcfg = globe_config(hw, mode)
        gx, gy = globe_offsets(x, y, mode)
        g = globe_fixed(gx, gy, globe_rotation(hw.config, frame), gcfg)
        inputs = {k: g[k] for k in ("u", "v", "n.phi", "n.theta")}
        if scene.mip_levels > 1:      # the globe's level, from its derivative
            inputs["level"] = g["level"]
        low = scene.tag_bits - 1
        inputs["tag"] = (count & ((1 << low) - 1)) | (g["inside"] << low)
    else:
        u, v = texel_coords(x, y, mode.zoom, scene.texture_size, scene.map_height)
        inputs = {"u": u, "v": v}
        inputs.update({k: np.full(n, c, np.int64) for k, c in plane_constants(scene).items()})
        inputs["tag"] = count & ((1 << scene.tag_bits) - 1)
    inputs.update({k: np.full(n, c, np.int64) for k, c in table[frame % len(table)].items()})
    if scene.mip_levels > 1 and "level" not in inputs:   # the plane reads level 0
        inputs["level"] = np.zeros(n, np.int64)
    return inputs


def golden_frame(scene, mode, frame, table, words, texels=None):
    """Frame ``frame`` as the board must show it: (v_active, h_active, 3) uint8 RGB (grey
    ``color`` of the shade, or the colour-texture blend's RGB)."""
    inputs = frame_inputs(scene, mode, frame, table)
    out = pipeline_fixed(inputs, scene, words, None, texels)
    if scene.texture:
        rgb = np.stack([out[f"color.{c}"] for c in "rgb"], -1)
    else:
        rgb = np.repeat(np.asarray(out["color"])[:, None], 3, axis=1)
    if surface(scene) == "sphere":                   # black outside the globe
        rgb = np.where((inputs["tag"] >> (scene.tag_bits - 1) & 1)[:, None] == 1, rgb, 0)
    return rgb.reshape(mode.v_active, mode.h_active, 3).astype(np.uint8)
