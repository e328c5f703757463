"""Python mutation with mutmut 3.8.1 on a random sample (``make mutate-py``).

Mutated: every Python file of rtl/, gen/ and sim/, drawn by area (:data:`AREAS`: the
configuration, the rest of the hardware, the golden models, the scenes, the testbenches, the
job runner, the rest of sim/, and each of gen/'s command line, flow, reports, benches and
renders) with at least ``--min-area`` mutants from each. mutmut, not cosmic-ray: it generates every mutant of a file in one
copy (trampolines switched by an environment variable, no re-import per mutant), records
which tests reach each function (its own coverage: a first run of the selected tests with
the trampolines counting calls) and runs each mutant only against those tests.

mutmut derives a mutant's module name from its file's path and refuses to run when the
tests import the code under another name. This repository installs ``rtl/`` as
``bumprtl.rtl`` (pyproject's ``[tool.setuptools.package-dir]``), so the runner lays out a
copy of the working tree as mutmut expects, ``bumprtl/{rtl,sim,gen,constraints}`` beside
``tests/``, with mutmut's configuration in the copy's ``setup.cfg`` (the repository's
pyproject.toml is not touched); mutmut then makes its ``mutants/`` copy of that and the
tests import ``bumprtl.*`` from there (it is first on sys.path, before the editable
install's finder).

A run: generate every mutant and record the tests per function (the tests of
:data:`TESTS`, the fast tiers that exercise these files, and the palette unit's tests,
which guard the palette table's golden model), draw a sample of ``--sample``
mutant names with ``random.Random(--seed)``, run mutmut on exactly those, and read each
one's result. Killed = a test failed (or timed out / crashed); survived = every test that
reaches the function passed; no tests = no selected test calls the function (counted as a
survivor: nothing guards it). Prints the kill ratio per area with the seed and saves the
run (``pymut_results_seed<S>_<commit>.json``); each survivor's diff is read from mutmut's
mutated copy (:func:`mutant_diff`, not ``mutmut show``, which took minutes a survivor).
``--doc`` writes the section between ``pymut:begin`` / ``pymut:end``: the command, the
table, every survivor with what it changes and why it is not killed (:data:`KNOWN`, or
"not read yet"); ``--doc-from`` writes it again from saved runs once their survivors are read.
"""

import argparse
import json
import os
import random
import shutil
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = {"rtl": "rtl", "sim": "sim", "gen": "gen", "constraints": "constraints"}
# every Python file of the three packages (the globs match subdirectories too)
MUTATE = ["bumprtl/rtl/*", "bumprtl/gen/*", "bumprtl/sim/*"]
# the areas of the stratified draw, each a prefix of mutmut's mutant names; the first that
# matches names a mutant's area, so a file's own area comes before its package's rest.
# docs/mutation.md lists them (tests/mutants/test_pymut_areas.py holds the two together)
AREAS = {"rtl/config.py": "bumprtl.rtl.config.", "rtl": "bumprtl.rtl.",
         "sim/golden": "bumprtl.sim.golden.",
         "sim/scenes/config.py": "bumprtl.sim.scenes.config.", "sim/scenes": "bumprtl.sim.scenes.",
         "sim/tb": "bumprtl.sim.tb.",
         "sim/other": "bumprtl.sim.",
         "gen/cli": "bumprtl.gen.cli.", "gen/flow": "bumprtl.gen.flow.",
         "gen/report": "bumprtl.gen.report.", "gen/bench": "bumprtl.gen.bench.",
         "gen/render": "bumprtl.gen.render.", "gen/formal": "bumprtl.gen.formal.",
         "gen/tools": "bumprtl.gen.tools."}
# the fast tiers of make test that reach those files (mutmut runs each mutant against the
# ones that call its function); tests/mutants is this tooling, tests/board the slow board run
# make test's selection but this tooling's own tests (tests/mutants) and the coverage map's
# (tests/tools): neither imports the package's code to check it
TESTS = ["tests/rtl", "tests/sim", "tests/gen", "tests/board", "tests/docs",
         "tests/docs_examples", "tests/test_add_a_method.py", "tests/test_cli_boundary.py",
         "tests/test_docs_made_at.py", "tests/test_docstrings_state_contracts.py",
         "tests/test_import_graph.py", "tests/test_sidecar_access.py"]
# imported once by the fork server (never the project's own modules: each worker imports
# those afresh, with the mutant switched on)
PRELOAD = ["numpy", "pytest", "hypothesis", "amaranth", "amaranth.hdl", "amaranth.sim", "PIL.Image",
           "scipy.spatial", "_pytest.python", "xdist"]
BEGIN, END = "<!-- pymut:begin -->", "<!-- pymut:end -->"
# laid out at the top of the copy (file in tests/mutants -> its name there): the cocotb
# benches run in a simulator's own Python, where mutmut's record sees nothing; these two
# bring its hits back to the test that started the simulator
SIM_RECORD = {"pymut_sim.py": "pymut_sim.py", "pymut_sitecustomize.py": "sitecustomize.py"}
# mutmut 3's exit codes per mutant (mutmut/__main__.py status_by_exit_code)
KILLED = {1, 3, -24, 24, 152, 255, 36, -9, 9, 37}     # test failed, timeout, killed, type check
SURVIVED, NO_TESTS = {0, 5}, {33}

# Survivors read so far: (function as mutmut mangles it, text of its mutated line, class,
# why no test kills it). Matched on the function and the changed text, not on mutmut's
# number (which moves when the function changes); --doc writes the reason beside each
# survivor of a draw and "not read yet" beside the others.
KNOWN = [
    ("bumprtl.gen.cli.flags.x_add_config_flags", "dest=None, action=argparse.BooleanOptionalAction",
     "equivalent", "argparse derives the same dest from `--flag-name` (the flag is the field's "
                   "name with `_` as `-`)"),
    ("bumprtl.gen.cli.main.x__optional", 'or "XXXX"', "equivalent",
     "the name is used only when OPTIONAL knows it, and it knows neither `\"\"` nor `\"XXXX\"`"),
    ("bumprtl.sim.golden.common.x_world_bump_normal", '"...JI,...J->...I"', "equivalent",
     "einsum's subscripts in capitals: the same contraction"),
    ("bumprtl.sim.golden.float.lee.x__lee", "np.errstate(invalid=None)", "equivalent",
     "only whether numpy warns changes, never a value (a warnings-as-errors run over 2,400 random "
     "and stress pixels passed with it)"),
    ("bumprtl.sim.golden.float.palette_quantize.x_nearest", "dtype=None", "equivalent",
     "the vectors are float64 already, and cKDTree converts"),
    ("bumprtl.sim.scenes.usermap.x_read_height", "np.asarray(img, dtype=None)", "equivalent",
     "the division by 255.0 or 65535.0 makes float64 anyway"),
    ("bumprtl.sim.scenes.config.xǁSceneConfigǁ__post_init__", '" OR ".join', "wording",
     "the list of methods in an error message joined by `OR`; the tests hold the refused key "
     "(`BumpError.field`) on purpose, not the wording"),
    ("bumprtl.gen.cli.flags.x_add_map_flags", "SURFACE THE MAP IS WRAPPED ON", "wording",
     "`--geometry`'s help text in capitals: what the help says is unchanged"),
    ("bumprtl.sim.golden.fixed.peercy.x_predicted_error_bound_lsb", "channel_bound(cfg, None, 0.0, e, lights)",
     "killed since", "no test asked Peercy's bound for a channel but diffuse; "
     "tests/sim/golden/fixed/test_bounds_closed_forms.py::test_peercys_other_channels_are_the_back_ends_bound_for_its_dot_error "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.float.palette.x_check_normal_map", 'name="XXnormalsXX"', "killed since",
     "the default name in an error message; tests/sim/golden/float/test_palette.py::test_a_bad_normal_map_is_named_normals "
     "reads the whole message (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.float.palette_quantize.x_kmeans", "seed=1):", "equivalent",
     "the seed only orders the points whose errors tie within the 1e-12 jitter when a centre "
     "empties; no input of the tests has such a tie, and a tie is equally bad either way"),
    ("bumprtl.sim.scenes.heightfields.x__skimage", "img = None", "missed by mutmut's record",
     "the closure is made when heightfields is imported, so mutmut credits _skimage to the test "
     "that ran then, not to the tests that load an image; "
     "tests/sim/scenes/test_scenes.py::test_texture_size_is_independent_of_image_size (in the "
     "selection) fails with the mutant switched on"),
    ("bumprtl.sim.scenes.usermap.x_load_bump_map", "float(height_scale), None, bool(resample)",
     "killed since", "no test of the selection asked load_bump_map for another size; "
     "tests/sim/scenes/test_usermap.py::test_load_bump_map_resamples_to_the_size_asked_for does "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.accuracy.x_crater_scene", "c = (np.arange(size) - 0.5) / size", "equivalent",
     "the unseen crater map sampled half a texel over: craters at uniform random centres, so "
     "the same kind of map translated by half a texel; nothing specifies where a crater sits"),
    ("bumprtl.sim.golden.stress.x_check_fixed", '"XXcolor_lsbXX"', "killed since",
     "no test read check_fixed's colour errors; "
     "tests/sim/golden/test_stress_cases.py::test_check_fixed_reports_diffuse_and_colour_errors_and_overflow_per_field "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.usermap.x_read_normals", "if np.any(None):", "killed since",
     "no test gave an RGBA normal map with a transparent texel; "
     "tests/sim/scenes/test_usermap.py::test_an_rgba_normal_map_is_read_only_when_opaque does "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", "maps = None", "killed since",
     "no test of the selection loaded a map without texture_size or with a second picture; "
     "tests/sim/scenes/test_config.py::test_a_users_map_sets_the_texture_size_and_refuses_a_second_picture "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.x__geometry", "u = phi / (2 * np.pi) / 2 * tex", "killed since",
     "no test read the cylinder's texel coordinates; "
     "tests/sim/scenes/test_scenes.py::test_texel_coordinates_of_each_geometry does (checked "
     "with the mutant switched on)"),
    ("bumprtl.gen.cli.flags.x_add_map_flags", 'metavar=None', "killed since",
     "`--texture-size`'s metavar (help only); "
     "tests/gen/cli/test_validation.py::test_every_map_flag_has_help_and_the_documented_metavar "
     "checks the T that docs/scenes.md writes (checked with the mutant switched on)"),
    ("bumprtl.gen.cli.flags.x_add_map_flags", "help=None)", "killed since",
     "a flag without its help line; "
     "tests/gen/cli/test_validation.py::test_every_map_flag_has_help_and_the_documented_metavar "
     "(checked with the mutant switched on)"),
    ("bumprtl.gen.cli.flags.x_add_map_flags", "MAP'S SIZE, OR THE SCENE'S", "wording",
     "the end of `--texture-size`'s help in capitals: what the help says is unchanged"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", 'keys.get("XXtexture_sizeXX")', "killed since",
     "no test of the selection gave a map with another texture_size; "
     "tests/sim/scenes/test_config.py::test_a_users_map_at_another_texture_size_is_resampled_or_refused "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", "(extra[0] == 'height_scale') or True", "killed since",
     "an error message calling a normal map's key a height map's; "
     "tests/sim/scenes/test_config.py::test_a_users_map_sets_the_texture_size_and_refuses_a_second_picture "
     "reads it (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", 'keys.get("TEXTURE_SIZE")', "killed since",
     "no test of the selection gave a map with another texture_size; "
     "tests/sim/scenes/test_config.py::test_a_users_map_at_another_texture_size_is_resampled_or_refused "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", "and {maps[1]} in {where}", "killed since",
     "an image and a map in one scene raised IndexError, not the one-line error; "
     "tests/sim/scenes/test_config.py::test_a_users_map_sets_the_texture_size_and_refuses_a_second_picture "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.xǁSceneConfigǁ_check_picture", '_choice("geometry", None, GEOMETRIES)',
     "killed since", "no test of draw 1's commit gave a scene a geometry; "
     "tests/sim/scenes/test_config.py::test_every_refusal_names_the_key_the_value_and_what_is_allowed "
     "(the refused 'torus' named in the message) kills it (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x__source_keys", "is_absolute()) and False", "killed since",
     "no test of the selection used a relative map path in a scene file; "
     "tests/sim/scenes/test_config.py::test_a_scene_files_map_path_is_relative_to_the_file "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.accuracy.x_adversarial_pixels", "(grid - 0.4999 * np.sign(grads[name]))",
     "killed since", "the search on the better side of the grid still finds nothing over the "
     "bound; tests/sim/golden/test_accuracy_search.py::test_adversarial_pixels_sit_on_the_side_that_moves_the_channel_most "
     "checks the side (checked with the mutant switched on)"),
    ("bumprtl.rtl.config.x__check_unit", "isinstance(value, bool) and not isinstance", "killed since",
     "ka = True passed as 1.0; no test gave a bool coefficient; "
     "tests/rtl/test_config.py::test_a_flag_of_the_wrong_type_is_refused_naming_field_and_value "
     "does (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.common.x_term_bounds_lsb", '"XXspecularXX": 0.0', "killed since",
     "no test of draw 1's commit asked a bound without specular (the key is then missing); "
     "tests/sim/golden/fixed/test_bounds_closed_forms.py::test_an_angle_error_a_moves_diffuse_255_a_and_specular_by_the_steepest_slope "
     "does (checked with the mutant switched on)"),
    ("bumprtl.rtl.config.x__check_int", 'why="XXXX"', "killed since",
     "every range without an explanation would end in '(XXXX)'; the tests read the refused "
     "field, not the message; tests/rtl/test_config.py::test_a_range_without_an_explanation_ends_at_the_range "
     "reads it (checked with the mutant switched on)"),
    ("bumprtl.rtl.config.xǁConfigǁ__post_init__", "B >= k - 1 = {k - 2}", "killed since",
     "the explanation's floor one below the range's; "
     "tests/rtl/test_config.py::test_the_frac_bits_floor_the_message_explains_is_the_range_it_gives "
     "(checked with the mutant switched on)"),
    ("bumprtl.rtl.config.xǁConfigǁ__post_init__", "*ANGLE_BITS_RANGE, )", "killed since",
     "angle_bits' range without its explanation; "
     "tests/rtl/test_config.py::test_a_range_without_an_explanation_ends_at_the_range "
     "(checked with the mutant switched on)"),
    ("bumprtl.rtl.config.xǁConfigǁ__post_init__", "==)", "killed since",
     "frac_bits' range without its explanation (the only mutant of __post_init__ whose whole "
     "change is a closing parenthesis); "
     "tests/rtl/test_config.py::test_the_frac_bits_floor_the_message_explains_is_the_range_it_gives "
     "(checked with the mutant switched on)"),
    ("bumprtl.rtl.config.xǁConfigǁ__post_init__", "raise ConfigError(None,", "killed since",
     "palette_blend's error said 'None'; the tests read the refused field only; "
     "tests/rtl/test_config.py::test_a_flag_of_the_wrong_type_is_refused_naming_field_and_value "
     "reads the message (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.peercy.x_normalize_fixed", "np.maximum(r, 2)", "equivalent",
     "r = isqrt(4 s) for an integer s is 0 or at least 2, never 1"),
    # draw 3 (seed 7)
    ("bumprtl.gen.cli.flags.x_add_map_flags", "YOUR OWN BUMP MAP (SIM/SCENES/USERMAP.PY)", "wording",
     "the title of the map flags' group in `--help` in capitals: what the help says is unchanged"),
    ("bumprtl.gen.cli.main.x_build_parser", "[{extra and need}] extra: ", "killed since",
     "a command listed with the extra of the missing package instead of its own; no test listed "
     "a command whose two differ; tests/gen/cli/test_packaging.py::test_the_command_list_names_a_commands_own_extra "
     "does (checked with the mutant switched on)"),
    ("bumprtl.rtl.config.xǁConfigǁ__post_init__", '_check_int("out_bits", self.out_bits, 8, 8, None)',
     "killed since", "out_bits' refusal without its reason; tests/rtl/test_config.py::test_out_bits_refusal_says_why "
     "reads it (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.float.palette.x_check_normal_map", "n.shape[0] != n.shape[1] or n.shape[1] == 0",
     "equivalent", "the clause before it already holds shape[0] == shape[1], so shape[1] == 0 "
     "is shape[0] == 0"),
    ("bumprtl.sim.golden.float.palette.x_displacement_to_normals", "h.size == 1:", "killed since",
     "an empty height map accepted and a 1 x 1 map refused; "
     "tests/sim/golden/float/test_palette.py::test_height_map_sizes_at_the_edges (checked with the "
     "mutant switched on)"),
    ("bumprtl.sim.golden.float.palette.x_quantize_normal_map", "(weights is None) or True", "killed since",
     "the use counts ignored (unused texels shaped the table); "
     "tests/sim/golden/float/test_palette.py::test_unused_texels_do_not_shape_the_table (checked "
     "with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x__source_keys", 'return dict(source), "SCENE"', "killed since",
     "a scene given as keys named 'SCENE' in its messages; "
     "tests/sim/scenes/test_config.py::test_messages_name_the_source_of_the_key (checked with the "
     "mutant switched on)"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", "if v is not None}, None,", "killed since",
     "a contradicting flag's message named the source 'None'; "
     "tests/sim/scenes/test_config.py::test_messages_name_the_source_of_the_key (checked with the "
     "mutant switched on)"),
    ("bumprtl.sim.scenes.imaging.x_compose", "np.asarray(color, None)", "equivalent",
     "every caller passes float64 intensities (the float references' and golden models' "
     "results), for which the conversion to float is the identity"),
    ("bumprtl.sim.scenes.usermap.x_normals_to_rgb", "n = np.asarray(normals, )", "killed since",
     "float32 normals rounded in float32 arithmetic (one texel in 65,536 of the test's map the "
     "other way); tests/sim/scenes/test_usermap.py::test_normals_to_rgb_rounds_float32_normals_as_given "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.usermap.x_read_normals", "np.linalg.norm(n, axis=None)", "killed since",
     "the texels divided by the map's one norm instead of each its own: the interpolation of a "
     "resampled map weighted by the 8-bit texels' lengths; "
     "tests/sim/scenes/test_usermap.py::test_resampling_interpolates_unit_normals (checked with "
     "the mutant switched on)"),
    # draw 4 (seed 8)
    ("bumprtl.gen.cli.flags.x_add_map_flags", '==g.add_argument("--texture-size", type=int, metavar="T",',
     "equivalent", "argparse's default for an option is None already"),
    ("bumprtl.gen.cli.flags.x_add_map_flags", "XXof heights; normals by Tarini", "wording",
     "`--height-map`'s help text with XX around its second half: what the flag does is unchanged"),
    ("bumprtl.gen.cli.flags.x_add_map_flags", "XXyour own bump map (sim/scenes/usermap.py)XX", "wording",
     "the title of the map flags' group in `--help` with XX around it"),
    ("bumprtl.gen.cli.main.x__optional", 'getattr(error, "name", )', "equivalent",
     "_optional is only given ImportErrors, and every ImportError has a `name` attribute (None "
     "when unknown), so getattr never needs its default"),
    ("bumprtl.rtl.config.xǁConfigǁreplace", "==)", "killed since",
     "replace's refusal of an unknown field without the field; "
     "tests/rtl/test_config.py::test_replace_names_the_unknown_field (checked with the mutant "
     "switched on)"),
    ("bumprtl.sim.golden.common.xǁPixelInputsǁ__post_init__", "if arr.min() < 1 else arr.max()",
     "killed since", "the message named the array's minimum (in range) instead of the value "
     "out of range; tests/sim/golden/float/test_models.py::test_bad_angles_are_named reads the "
     "value now (checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.common.x_angle_codes", "np.asarray(angle_rad, ) *", "killed since",
     "float32 angles quantized in float32 arithmetic; "
     "tests/sim/golden/test_stress_cases.py::test_angle_codes_round_float32_angles_as_given "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.common.x_polar_illumination_fixed", '"NDOTH": ndoth', "killed since",
     "the polar back end's N'.H under another key; no test read it; "
     "tests/sim/golden/fixed/test_lee.py::test_polar_illumination_reports_the_dots_its_shades_come_from "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.peercy.x_isqrt", "r + 2, r)", "equivalent",
     "the upward fix never runs below 2**62: float64 rounds x by a relative 2**-53 and its "
     "sqrt by another 2**-53, so sqrt(float(x)) >= r (1 - 2**-53) with r = isqrt(x), which "
     "is within half a float64 step below r (2**-53 r) and rounds to r or above: the "
     "estimate is never low"),
    ("bumprtl.sim.scenes.config.x__merge", "if key not in _PICTURE_KEYS:", "killed since",
     "the picture clash checked for every key but the pictures; "
     "tests/sim/scenes/test_config.py::test_only_a_second_picture_clashes_with_the_scenes_picture "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", '"ROTATION": None', "killed since",
     "a SceneConfig with overrides refused (an unknown key); "
     "tests/sim/scenes/test_config.py::test_a_scene_config_loads_as_itself_and_takes_overrides "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.config.xǁSceneConfigǁ__post_init__", "16 <= t <= 4097", "equivalent",
     "4097 is not a power of two, which the same condition refuses (`t & (t - 1)`)"),
    ("bumprtl.sim.scenes.imaging.x_max_diff", "np.asarray(img, ))))", "equivalent",
     "ref is made int, so ref - img is int64 for the 8-bit images every caller passes"),
    ("bumprtl.sim.scenes.usermap.x_write_png", 'chunk(b"iend", b"")', "killed since",
     "a PNG ended by an unknown ancillary chunk instead of IEND (Pillow reads it, but its "
     "check refuses it); tests/sim/scenes/test_usermap.py::test_written_pngs_pass_a_decoders_check "
     "(checked with the mutant switched on)"),
    # seed 9
    ("bumprtl.gen.cli.flags.x_add_map_flags", "opengl = +y up the image", "wording",
     "`--normal-convention`'s help with the axis +Y written +y: what the help says is unchanged"),
    ("bumprtl.gen.tools.docs.x_made_at", 'note="XXXX"', "killed since",
     "no test of the selection called made_at (tests/test_docs_made_at.py is outside it); "
     "tests/gen/tools/test_docs.py::test_made_at_records_both_widths_and_a_note_only_when_given "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.accuracy.x__target", "(value > 0.5) | (value < 254.5)", "killed since",
     "every value counted as unclamped, 0 and 255 too; the searches' tests still found pixels "
     "under the bound; tests/sim/golden/test_accuracy_search.py::test_the_search_targets_only_channel_values_inside_the_clamps "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.accuracy.x_arithmetic_pixels", "0, full / 2),", "equivalent",
     "the clip's upper end as a float makes the theta codes float64, of the same integer "
     "values (below 2**53), and on_grid multiplies them by the step either way"),
    ("bumprtl.sim.golden.accuracy.x_arithmetic_pixels", "x + 1.000001)", "killed since",
     "the side of each angle chosen from a difference over 1 rad instead of 1e-6 (the sign of "
     "d N'.H' / d angle lost); no test read the side; "
     "tests/sim/golden/test_accuracy_search.py::test_arithmetic_pixels_shift_each_angle_the_way_the_arithmetic_error_goes "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.common.x_to_8bit", "np.asarray(x, ), nan=0.0)", "killed since",
     "float32 intensities rounded in float32 arithmetic; "
     "tests/sim/golden/test_stress_cases.py::test_to_8bit_rounds_float32_intensities_as_given "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.common.x_shade_fixed", "fine = np.zeros_like(None)", "killed since",
     "without specular the specular outputs a 0-d object 0 instead of an integer 0 per pixel; "
     "no test shaded without specular at this level; "
     "tests/sim/golden/fixed/test_rounding.py::test_shade_without_specular_is_zero_in_every_pixel "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.golden.fixed.exact.x_rotation_fixed", "c = lambda a: None", "killed outside the selection",
     "the TABLE_READ hook's cosine reads: only the coverage frame's table-sensitivity search "
     "(sim/tb/bulk_frame.py) sets the hook, so only make test's tests/sim/tb tests that build "
     "a coverage frame reach it, and with the mutant switched on building the frame raises "
     "TypeError: tests/sim/tb/test_bulk_scene_frames.py::test_scene_coverage_frame_equals_golden[diffuse] "
     "fails (checked); the hook has no use outside that search for a fast test to check"),
    ("bumprtl.sim.golden.fixed.lee.x_rotate_fixed", "k + 2 * b - 2 <= 63", "equivalent",
     "the two guards differ only at k + 2B = 62 (angle_bits 16, frac_bits 24, the largest "
     "Config allowed), where |y2| <= 2**25 and the reciprocal ROM's words have 38 bits: the "
     "product |y2| x 1/|sin| is below 2**63 and int64 holds it (200,000 random inputs there "
     "gave the same codes)"),
    ("bumprtl.sim.golden.fixed.peercy.x_isqrt", "(r + 2) * (r + 1) <= x", "equivalent",
     "the upward fix never runs below 2**62 (the float64 estimate is never low: the reason "
     "given for this line's `r + 2, r)` mutant), so a stricter condition for it changes nothing"),
    ("bumprtl.sim.golden.float.palette_quantize.x__renormalize", "np.array(table, dtype=None)",
     "equivalent", "both callers pass float64 tables (np.average of float64 points, and "
     "bincount sums divided by weights), which np.array copies as float64 anyway"),
    ("bumprtl.sim.scenes.config.x_load_scene_config", "value is None and not (maps", "killed since",
     "defaults with a value ignored and None defaults set; no test of the selection passed "
     "defaults; tests/sim/scenes/test_config.py::test_defaults_fill_only_the_keys_nothing_sets "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.heightfields.x__band_limited", "k = None", "killed since",
     "no test drew wood or text below 64 texels; "
     "tests/sim/scenes/test_heightfields.py::test_small_wood_and_text_are_the_64_texel_fields_averaged_over_blocks "
     "does, but the decorator runs when heightfields is imported, so mutmut credits it to no "
     "test (seed 9 at ecee408 kept it); "
     "tests/sim/scenes/test_heightfields.py::test_band_limiting_averages_detail_finer_than_a_texel "
     "calls _band_limited itself (checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.heightfields.x__skimage", "img.resize((t, t), )", "missed by mutmut's record",
     "the closure is made when heightfields is imported, so mutmut credits _skimage to the "
     "test that ran then; and the mutant is Pillow's default filter (bicubic, also "
     "antialiased) for Lanczos on scikit-image's pictures, which nothing specifies (docs/scenes.md "
     "names Lanczos for a user's map, sim/scenes/usermap.py): a test could only repeat the call"),
    ("bumprtl.sim.scenes.usermap.x_map_size", "_load_npy(None, raw)", "killed since",
     "a bad .npy's message from map_size named 'None' instead of the file; "
     "tests/sim/scenes/test_usermap.py::test_map_size_of_a_bad_npy_names_the_file "
     "(checked with the mutant switched on)"),
    ("bumprtl.sim.scenes.heightfields.x__narrow", "BRICK_BEVEL * t / 17 <= 0.5", "equivalent",
     "the narrow/wide switch moves from t = 66.7 to 70.8 texels and map sides are powers of two: "
     "no side lies between"),
    ("bumprtl.sim.scenes.heightfields.x_brick_lines", "(j + 1.5 * (k % 2))", "equivalent",
     "modulo the map side the same four joint columns, in another order, which nothing specifies"),
    ("bumprtl.sim.scenes.usermap.x_nearest_allowed_size", "np.log2(side) - 1e-9", "equivalent",
     "no integer side has a log2 within 1e-9 of a half (both forms give the same size for every "
     "side from 1 to 200,000)"),
    ("bumprtl.sim.golden.common.x_cartesian_to_polar", "==v = np.asarray(v, )", "equivalent",
     "float64 input is unchanged and integer input gives the same angles: the norm, the division "
     "and arctan2 return float64"),
    ("bumprtl.sim.golden.float.palette_quantize.x_distinct", "np.asarray(vectors, dtype=None)",
     "equivalent", "every caller passes float64 vectors (the normal maps' unit vectors)"),
    ("bumprtl.sim.golden.float.palette_quantize.x_kmeans", "iterations=13", "not specified",
     "k-means stops when its table stops changing; one more allowed iteration changes nothing on "
     "a table that settles within 12, and the docstring names no count"),
    ("bumprtl.sim.golden.measure.x_worst_pixel", "seed=2", "not specified",
     "the default seed of the sample: any seed draws a valid sample, and every caller passes its own"),
    ("bumprtl.sim.golden.float.palette.x_render_palette", "lighting, None)", "killed since",
     "no test rendered with dithering, so dropping `dither` went unseen; "
     "tests/sim/golden/float/test_palette_props.py::test_render_palette_dithers_when_asked "
     "(checked with the mutant switched on)"),
    ("bumprtl.gen.cli.flags.x_add_config_flags", "parser.add_argument(flag, action=argparse.BooleanOptionalAction,",
     "equivalent", "argparse derives the same dest from `--flag-name` (the flag is the field's "
                   "name with `_` as `-`)"),
    ("bumprtl.sim.scenes.usermap.x__resize", "np.asarray(channels, None)", "equivalent",
     "each plane is cast to float32 for Pillow's resize whatever the array's dtype, and the "
     "result is read back as float64"),
    ("bumprtl.sim.scenes.x__brick_albedo", "np.clip(height, None, 1)", "equivalent",
     "the brick field is clipped to [0, 1] where it is made (sim/scenes/heightfields.bricks), so "
     "no height is below 0"),
    ("bumprtl.sim.golden.accuracy.x_arithmetic_pixels", "/ cfg.one + conventional(p, cfg).ndoth",
     "killed since", "step 1 then kept only the N' whose model overshoots N'.H' (the sum is "
     "dominated by the positive errors); "
     "tests/sim/golden/test_accuracy_builders.py::test_arithmetic_pixels_keep_errors_of_both_polarities "
     "(checked with the mutant switched on)"),
    # seed 33 (the first draw with make test's whole selection): each "killed since" checked
    # with its mutant switched on
    ("bumprtl.gen.bench.rtl_sim.x_rtl_sim_bench", "json.dumps(rows, indent=None)", "equivalent",
     "rows.json holds the same JSON on one line: only the whitespace changes, and its readers "
     "parse it"),
    ("bumprtl.gen.bench.sweep.x_plot", "strict=None", "equivalent",
     "zip's strict takes a truth value: None is false, as False is"),
    ("bumprtl.gen.tools.toolchain.x_roms_as_readmemh", "v.replace('XX_XX', '')", "equivalent",
     "int() accepts the underscores of a Verilog literal itself (PEP 515), so removing them "
     "first or not gives the same word"),
    ("bumprtl.rtl.ecp5.xǁECP5Loweringǁram", "one = Const(0, 1), Const(1, )", "equivalent",
     "Const(1) is one bit wide already"),
    ("bumprtl.gen.cli.formal.x_run", "==merge=args.merge, from_results=args.from_results, doc=args.doc)",
     "killed since", "no test ran `bumprtl formal` with --out; "
     "test_bumprtl_formal_hands_every_flag_to_the_runner passes every flag"),
    ("bumprtl.gen.flow.vectors.x__emit_named", "None,", "killed since",
     "no test compared vectors' design with emit's; "
     "test_the_design_vectors_writes_is_emit_pipelines_with_named_ports does (and found its "
     "sidecar's command without --ports named)"),
    ("bumprtl.gen.formal.doc.x__write_section", "XX--from-resultsXX", "killed since",
     "test_the_page_names_the_command_its_rows_came_from"),
    ("bumprtl.gen.formal.run.x_check_axi", "name=None", "killed since",
     "test_the_axi_covers_are_covered_or_not now checks the job's name and depth"),
    ("bumprtl.gen.formal.run.x_check_mutant", "(prop == \"bank\") and False", "killed since",
     "test_a_broken_unit_of_the_bank_property_gets_the_memories_mapped"),
    ("bumprtl.gen.formal.run.x_formal_job", "p.resolve() != Path(row.trace).resolve()", "killed since",
     "test_a_formal_job_keeps_the_sby_logs_and_the_trace_only"),
    ("bumprtl.gen.report.fpga.x__plot", 'r["row"] != "pipeline"', "killed since",
     "tests/docs/test_fpga_pages.py now reads the plot's points and names"),
    ("bumprtl.gen.report.table1.x__count_row", "mults = None", "killed outside the selection",
     "test_the_page_is_docs_table1_md_but_for_the_numbers fails with it, but the page is "
     "written by the module's fixture, and mutmut credits what a module-scoped fixture calls "
     "to the first test that uses it only (test_lee_counts_agree_with_the_paper_where_they_should, "
     "which parses the numbers and passes)"),
    ("bumprtl.gen.report.table1.x_count_all", 'desc="XXcountXX"', "wording",
     "the progress bar's label on stderr"),
    ("bumprtl.gen.tools.jobs.xǁRunnerǁ__init__", "(progress is None) or True", "killed since",
     "test_progress_follows_the_argument_then_the_environment"),
    ("bumprtl.gen.tools.jobs.xǁRunnerǁrun", "Outcome(None, error=", "killed since",
     "test_a_job_without_a_result_is_an_error_outcome_named_after_it"),
    ("bumprtl.gen.tools.jobs.xǁRunnerǁrun", "outcome = Outcome(error=", "killed since",
     "test_a_job_without_a_result_is_an_error_outcome_named_after_it"),
    ("bumprtl.gen.tools.sby.x_run_sby", "seconds, None, trace", "killed since",
     "test_a_failure_gives_its_assertions_and_the_last_trace checks the run directory"),
    ("bumprtl.rtl.sdram.xǁSdramConfigǁ__post_init__", "self.init_refreshes <= 17", "killed since",
     "every range end of SdramConfig is tested on both sides now"),
    ("bumprtl.rtl.shade.xǁBackEndǁ__init__", "credit=False", "killed since",
     "test_a_unit_built_from_its_configuration_alone_has_its_own_credit_edge"),
    ("bumprtl.sim.golden.float.palette.x__environment", "np.array([1.45, 0.3, 0.15])", "killed since",
     "test_the_chrome_environment_is_a_colour_brown_below_and_blue_above"),
    ("bumprtl.sim.scenes.usermap.x_read_normals", "_sized(path, n, size, resample, )", "killed since",
     "test_a_non_square_normal_map_keeps_its_shape_and_content"),
    ("bumprtl.sim.sdram_model.xǁSdramModelǁ_write", "self.n + self.bl - 2", "killed since",
     "test_a_column_command_may_follow_a_burst_exactly_when_it_ends"),
    ("bumprtl.gen.cli.emit.x_run", "==images = None", "killed since",
     "no test emitted a scene unit through the CLI with --interface axis and looked at its map; "
     "test_an_axis_scene_unit_carries_the_maps_the_stream_one_does"),
    ("bumprtl.gen.flow.resources.x__count_macc", "_constant(x) in (None, 0)", "killed since",
     "test_a_macc_has_a_constant_adder_only_for_a_nonzero_constant_addend"),
    ("bumprtl.gen.render.rtl.x__palette_maps", 'color_table(qmap.table, "phong", l, v, )', "killed since",
     "test_a_palette_scenes_colour_table_is_shaded_with_the_scenes_coefficients"),
    ("bumprtl.sim.formal.sdram.xǁSdramCommandContractǁelaborate", '"burst: read after read"', "wording",
     "a cover's name, printed when it is not reached"),
    ("bumprtl.gen.flow.named.x_named_wrapper", "XX  /* verilator lint_off UNUSEDSIGNAL */XX",
     "equivalent", "the branch for an output payload with bits outside every field: no design "
     "emits one today (every unit, method and built-in scene pipeline emitted with --ports named "
     "was tried), so the waiver is never written"),
    ("bumprtl.gen.render.rtl.x_render_rtl", "build_dir, progress=None, texels=texels,", "not specified",
     "only the per-cycle render passes it on, which make test does not run (make regress's "
     "per-cycle renders do not read their progress lines); the progress output is not specified "
     "by a test"),
    ("bumprtl.rtl.pipeline.xǁBumpPipelineǁ_plan_shading", "==None)", "killed since",
     "no test read the reasons the sidecar gives for each unit built; "
     "test_every_unit_a_scene_pipeline_builds_says_why_it_is_there"),
    ("bumprtl.rtl.config.xǁConfigǁ__post_init__", '_check_int("lights", 1, 8)', "stopped",
     "the run was stopped while this mutant's tests ran: _check_int takes the value and both "
     "ends, so every Config raises TypeError and every test that builds one fails"),
    ("bumprtl.sim.formal.axi.x_bmc", '"bmc", None)', "make formal",
     "the AXI contract's BMC runs only in make formal (its broken managers and the fallback "
     "of its proofs); make test proves the rules by induction"),
    ("bumprtl.sim.formal.mutants.xǁSwapAheadPaletteǁelaborate", "self.i.ready.eq(None)", "make formal",
     "a broken unit built for make formal's bank proofs; make test runs three others"),
    ("bumprtl.sim.formal.contract.xǁStreamContractǁ_fifo_lemmas", "(produce < n) | (consume < n)",
     "equivalent", "a weaker auxiliary lemma: it is still true, and the properties proved with "
     "it (order, credit) are the same; only the induction's help is weaker, and it still closes"),
    # seed 34
    ("bumprtl.gen.bench.memory.x__page", "_worst(rows, 20, None)", "killed since",
     "the summary's throughputs were only checked to be numbers; "
     "tests/gen/bench/test_memory.py::test_the_page_quotes_the_worst_case_of_each_cache_at_each_latency"),
    ("bumprtl.gen.cli.emit.x_run", "lint(wrapper, )", "killed since",
     "no test ran emit --lint with a wrapper; "
     "tests/gen/flow/test_named_ports.py::test_emit_lint_lints_each_wrapper_with_the_design_it_wraps"),
    ("bumprtl.gen.cli.reference.x_main", "print(None)", "killed since",
     "tests/gen/cli/test_reference.py::test_check_says_current_or_stale_and_writes_nothing reads "
     "each of the three messages word for word now"),
    ("bumprtl.gen.cli.render.x_render_scene", '"shading": "--METHOD"', "killed since",
     "no test read which flag a contradiction names; tests/gen/render/test_render.py::"
     "test_a_render_flag_that_contradicts_the_scene_file_is_named"),
    ("bumprtl.gen.flow.board.x__run_verilator", "stamp.is_file() or stamp.read_text()", "killed since",
     "tests/gen/flow/test_board_flow.py::test_the_board_bench_is_built_again_exactly_when_its_digest_changes"),
    ("bumprtl.gen.flow.board.x_bram_budget", 'surface(scene) != "sphere"', "killed since",
     "tests/gen/flow/test_board_flow.py::test_only_a_globe_budgets_its_latitude_roms"),
    ("bumprtl.gen.flow.board.x_check_frames", "11 * round(1e11 / m.pixel_hz)", "killed since",
     "the bench's frames stay equal with a pixel clock 10 % slow (the pipe clock follows it); "
     "tests/gen/flow/test_board_flow.py::"
     "test_the_board_bench_runs_the_modes_pixel_clock_and_the_pipes_ratio"),
    ("bumprtl.gen.flow.fpga.x_place_and_route", "==target = None", "killed since",
     "the success path ran only under make fpga; tests/gen/flow/test_fpga.py::"
     "test_a_placement_row_holds_the_lpf_target_and_whether_it_was_met (the tools stood in)"),
    ("bumprtl.gen.flow.resources.x_count_netlist", '["XXBXX"]', "killed since",
     "make test's netlists hold products as $macc only; tests/gen/flow/test_resources.py::"
     "test_a_mul_cell_is_counted_as_a_macc_product_is"),
    ("bumprtl.gen.render.images.x_fixed_image", "golden_render(s, None,", "killed since",
     "no test rendered the palette method on a textured scene; tests/gen/render/test_render.py::"
     "test_fixed_palette_of_a_textured_scene_is_the_pipelines_golden_render"),
    ("bumprtl.gen.render.rtl.x_render_rtl", "XXRTL render: pixel tags", "wording",
     "the message of an internal check (a pipeline that loses or duplicates pixels); the "
     "tests reach the check's passing side only"),
    ("bumprtl.gen.render.rtl.x_run_pipeline_emitted", "run_cocotb(v, ", "killed since",
     "the per-cycle render ran only in make regress; tests/sim/tb/test_tb_pipeline.py::"
     "test_render_rtl_per_cycle_equals_golden_bytes"),
    ("bumprtl.gen.report.fpga.x__plot", "figsize=(6, 3.5)", "killed since",
     "the plot's content was checked, not its picture; tests/docs/test_fpga_pages.py::"
     "test_the_report_page_is_written_again_from_its_rows compares the picture's size with "
     "the one the page shows"),
    ("bumprtl.gen.report.recommend.x_rank_key", "point.get(k, ) or 0", "killed since",
     "no tie case had a point whose widths are only in its config (a palette point's); "
     "tests/gen/report/test_ties.py's 'widths read from the configuration' case"),
    ("bumprtl.gen.report.timing.x_scenarios", '"STALL": list(stall)', "killed since",
     "no test read the scenarios' facts; tests/gen/report/test_timing.py::"
     "test_the_stall_facts_are_the_cycles_its_trace_holds_o_ready_low"),
    ("bumprtl.gen.tools.objcache.x__store", "shutil.rmtree(tmp, ignore_errors=False)", "equivalent",
     "tmp is renamed into place before the finally clause, so the rmtree raises "
     "FileNotFoundError, an OSError, which main() catches as it catches a cache that cannot "
     "be written: the entry is stored and the compile returns 0 either way"),
    ("bumprtl.sim.formal.contract.xǁStreamContractǁ_bank", "==valid = None", "make formal",
     "the bank property of a scene pipeline (its fetch stages' valid bits) is proved in make "
     "formal; make test proves PaletteLUT's alone"),
    ("bumprtl.sim.formal.contract.xǁStreamContractǁ_cache_order", "TAG_CACHE_HEAD_REGISTER",
     "make formal", "a lemma of the cached pipeline's order proof (232 s), make formal's"),
    ("bumprtl.sim.formal.sdram.x_cover", '"COVER", depth)', "make formal",
     "the SDRAM contract's covers run in make formal; make test proves its rules"),
    ("bumprtl.sim.golden.globe.x_check_against_float", "if (diff.size) or True else 0", "killed since",
     "tests/rtl/test_globe.py::test_model_against_float_of_pixels_all_outside_the_disc"),
    ("bumprtl.sim.tb.bulk_wrapper.x_setup_writes", "((1 >> w) - 1)", "killed since",
     "the copy of pack() it was in is gone: setup_writes calls rtl/layouts.pack, and "
     "tests/rtl/test_layouts_pack.py fails with the same change there (a negative low field "
     "spilling into the fields above it)"),
    ("bumprtl.gen.cli.main.x_build_parser", 'dest="COMMAND"', "equivalent",
     "the command's name is stored under dest and never read: each command's parser sets "
     "func, and a missing command is refused by argparse with the metavar, COMMAND, either way"),
    ("bumprtl.sim.scenes.heightfields.x_normals_from_gradient", "-np.asarray(dh_dv, )", "equivalent",
     "its one caller, height_to_normals, passes float64 slopes (it casts the heights first); "
     "for them asarray without a dtype is the same array"),
    ("bumprtl.sim.golden.fixed.common.x_specular_fine_fixed", "specular_base(cfg, None)",
     "killed since", "no test read the golden model at a table step other than the RTL's (bench "
     "specular's candidates); tests/rtl/test_tables.py::"
     "test_every_table_step_reads_its_own_words_from_x0_to_one"),
    ("bumprtl.sim.scenes.config.xǁSceneConfigǁ__post_init__", '"TEXTURE_HEIGHT")', "killed since",
     "tests/sim/scenes/test_config_rules.py::"
     "test_a_palette_scene_of_a_non_square_map_is_refused_naming_texture_height"),
    ("bumprtl.gen.flow.units.x_faithful_widths", "cfg if (cfg.specular) or True else", "equivalent",
     "without specular no channel's bound involves the exponent, so the search gives the same "
     "widths at every exponent; setting it to 1 only lets one cached search serve them all"),
    ("bumprtl.sim.tb.tb_sdram.x_start", 'unit="PS"', "equivalent",
     "cocotb lower-cases a time unit before it looks it up (cocotb/simtime.py)"),
]


def committed_tree(dest, rev="HEAD"):
    """The committed tree (git archive REV) in ``dest``: others may be editing the working
    tree meanwhile, and a sample is only reproducible on a commit."""
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    archive = subprocess.run(["git", "archive", rev], cwd=ROOT, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    commit = subprocess.run(["git", "rev-parse", "--short", rev], cwd=ROOT, capture_output=True,
                            text=True, check=True).stdout.strip()
    return [str(f.relative_to(dest)) for f in dest.rglob("*") if f.is_file()], commit


def lay_out(dest, src, files):
    """The copy mutmut expects: bumprtl/<package>/..., tests/ (setup.cfg: :func:`configure`)."""
    if dest.exists():
        shutil.rmtree(dest)
    for name in files:
        top = name.split("/", 1)[0]
        if top in PACKAGES:
            target = dest / "bumprtl" / PACKAGES[top] / name.split("/", 1)[1]
        elif top in ("tests", "pyproject.toml", "CHANGELOG.md", "docs"):
            # test_version reads the changelog; the map flags' help, the integration page's
            # and the reports' tests read pages of docs/
            target = dest / name
        else:
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src / name, target)
    (dest / "bumprtl" / "__init__.py").write_text("")
    # the record's hits from the simulators' processes (pymut_sim.py, pymut_sitecustomize.py)
    for name, as_name in SIM_RECORD.items():
        shutil.copy2(src / "tests" / "mutants" / name, dest / as_name)
    # tests/mutants is this tooling, not tests to run
    shutil.rmtree(dest / "tests" / "mutants", ignore_errors=True)


# in the laid-out copy but not of the commit: mutmut's own files and the runner's
OWN = {"mutants", "setup.cfg", "preload_modules.txt", ".commit"}


def update_tree(tree, src, files):
    """Lay out another commit over a copy mutmut has already mutated, so that it generates
    again only the files the commit changed (it regenerates a file whose source is newer
    than its mutated copy, and mutating every file takes tens of minutes). Changed and new
    files are copied with the current time, removed files go from both copies, and the
    results and test record of the old commit are dropped (its tests may differ). Returns
    the paths changed."""
    new = tree.parent / "tree.new"
    lay_out(new, src, files)
    changed, now = [], time.time()
    for f in sorted(p for p in new.rglob("*") if p.is_file()):
        rel = f.relative_to(new)
        old = tree / rel
        if not old.is_file() or old.read_bytes() != f.read_bytes():
            old.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(f, old)
            os.utime(old, (now, now))
            changed.append(str(rel))
            if rel.parts[0] == "bumprtl" and rel.suffix != ".py" and (tree / "mutants").is_dir():
                # mutmut copies a package's other files (Verilog templates, C++) into its
                # copy only when it first makes it: a changed one goes there now
                (tree / "mutants" / rel).parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(f, tree / "mutants" / rel)
    for f in sorted(p for p in tree.rglob("*") if p.is_file()):
        rel = f.relative_to(tree)
        if rel.parts[0] in OWN or (new / rel).exists():
            continue
        f.unlink()
        for gone in (tree / "mutants" / rel, tree / "mutants" / f"{rel}.meta"):
            gone.unlink(missing_ok=True)
        changed.append(f"{rel} (removed)")
    shutil.rmtree(new)
    (tree / "mutants" / "mutmut-stats.json").unlink(missing_ok=True)
    for meta in (tree / "mutants").rglob("*.meta"):
        data = json.loads(meta.read_text())
        data["exit_code_by_key"] = dict.fromkeys(data.get("exit_code_by_key", {}))
        meta.write_text(json.dumps(data))
    return changed


def selected_tests(dest, tests=None):
    """The tests (default TESTS) that the commit has (the scene tests moved with the scene
    module)."""
    tests = tests or TESTS + ["tests/rtl/test_scene.py"]
    return [t for t in tests if (dest / t).exists()]


def failing_tests(dest, env, log, tests=None, jobs=1, recording=False):
    """The selected tests that fail on the unmutated commit (mutmut needs a green run):
    their node ids, to deselect and to list. ``jobs`` pytest workers (``-j``: no more
    processes than the mutants themselves get). ``recording``: with the trampolines
    counting calls, as in mutmut's record (``MUTANT_UNDER_TEST=stats``, run in its
    ``mutants/`` copy, whose setup.cfg the trampolines read): a test can fail there only,
    and mutmut's record stops at its first failure without saying which."""
    plugin = ["-p", "pymut_sim"] if recording else []
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-rf", "-n", str(jobs), "-p", "no:cacheprovider",
                        *plugin, "-m", "not regress and not fpga and not formal", *selected_tests(dest, tests)],
                       cwd=dest, env={**env, "PYTHONPATH": str(dest),
                                      "MUTANT_UNDER_TEST": "stats" if recording else ""},
                       capture_output=True, text=True)
    with open(log, "a") as f:
        f.write("\n$ baseline pytest\n" + r.stdout[-3000:] + r.stderr[-2000:])
    return sorted({l.split()[1] for l in r.stdout.splitlines() if l.startswith("FAILED ")})


def configure(dest, deselect, only=None, tests=None):
    cfg = ["[mutmut]", "source_paths = bumprtl", "only_mutate ="]
    cfg += [f"    {p}" for p in (only or MUTATE)]
    cfg += ["pytest_add_cli_args_test_selection ="] + [f"    {t}" for t in selected_tests(dest, tests)]
    cfg += ["pytest_add_cli_args =", "    -p", "    no:cacheprovider", "    -p", "    no:xdist",
            "    -p", "    pymut_sim",
            "    -m", "    not regress and not fpga and not formal",
            *[x for d in deselect for x in ("    --deselect", f"    {d}")],
            # mutmut runs the tests in mutants/, which holds the package and tests/ only:
            # tests/gen/cli/test_packaging.py::test_version reads the changelog beside them,
            # tests/gen/cli/test_flags_roundtrip.py docs/scenes.md
            "also_copy =", "    CHANGELOG.md", "    docs", *[f"    {n}" for n in SIM_RECORD.values()],
            "use_git_change_detection = false", "timeout_multiplier = 5.0",
            # each mutant's tests run in a process forked from a server that imported the
            # third-party modules only: forked from mutmut's own process (its default), a
            # worker inherits what the clean run left there, the lru_caches of the golden
            # models' bounds among it, and a mutant behind a filled cache passes every test
            "process_isolation = forkserver", "forkserver_warmup = import",
            # a worker imports the project and collects its tests before the first one runs
            # (seconds of CPU): mutmut's CPU limit, (tests' time + constant) x 2 x multiplier,
            # with its constant of 1 s timed out mutants on that alone
            "timeout_constant = 20.0",
            f"preload_modules_file = {dest.resolve() / 'preload_modules.txt'}", ""]   # read from mutants/
    (dest / "setup.cfg").write_text("\n".join(cfg))
    (dest / "preload_modules.txt").write_text("\n".join(PRELOAD) + "\n")
    # pyproject's [tool.pytest] stays (markers, test paths); mutmut reads setup.cfg only
    # when pyproject has no [tool.mutmut]


def mutmut(args, cwd, env, log):
    exe = str(Path(sys.executable).parent / "mutmut")
    with open(log, "a") as f:
        f.write(f"\n$ mutmut {' '.join(args[:8])}{' ...' if len(args) > 8 else ''}\n")
        f.flush()
        return subprocess.run([exe, *args], cwd=cwd, env=env, stdout=f, stderr=subprocess.STDOUT).returncode


def all_results(tree):
    """{mutant name: exit code or None} from mutmut's .meta files."""
    out = {}
    for meta in (tree / "mutants").rglob("*.meta"):
        data = json.loads(meta.read_text())
        out.update(data.get("exit_code_by_key", {}))
    return out


def area(name):
    for label, prefix in AREAS.items():
        if name.startswith(prefix):
            return label
    return "other"


def draw(names, size, seed, min_area):
    """``size`` mutant names drawn with ``random.Random(seed)``, stratified by area: each
    area gets ``min_area`` of its mutants (all if it has fewer), the rest of the sample is
    shared in proportion to the mutants each area has left (largest remainders), and each
    area's share is a uniform draw from its own mutants. Without the floor the small areas
    (the command line: about 2 % of the mutants) are often not drawn at all."""
    rng = random.Random(seed)
    by_area = defaultdict(list)
    for n in sorted(names):
        by_area[area(n)].append(n)
    labels = [l for l in [*AREAS, "other"] if by_area[l]]
    size = min(size, len(names))
    quota = {l: min(len(by_area[l]), min_area) for l in labels}
    if not min_area or sum(quota.values()) > size:     # no floor (or floors above the sample):
        # a plain uniform draw
        return sorted(rng.sample(sorted(names), size))
    left = {l: len(by_area[l]) - quota[l] for l in labels}
    rest, pool = size - sum(quota.values()), sum(left.values())
    if rest and pool:
        exact = {l: rest * left[l] / pool for l in labels}
        for l in labels:
            quota[l] += int(exact[l])
        for l in sorted(labels, key=lambda l: int(exact[l]) - exact[l])[:rest - sum(int(v) for v in exact.values())]:
            quota[l] += 1
    return sorted(n for l in labels for n in rng.sample(by_area[l], quota[l]))


def command_line(argv):
    return "python tests/mutants/pymut.py " + " ".join(argv if argv is not None else sys.argv[1:])


_MODULES = {}     # module path -> its functions' lines, parsed once a run


def mutant_diff(tree, name, _modules=_MODULES):
    """The lines a mutant changes (``-`` original, ``+`` mutant), from mutmut's mutated copy
    of its module: the ``..._mutmut_orig`` and ``..._mutmut_N`` functions found with ast
    (one parse a module, milliseconds), diffed with difflib."""
    import ast
    import difflib
    module, _, func = name.rpartition(".")
    base = tree / "mutants" / Path(*module.split("."))
    path = base.with_suffix(".py") if base.with_suffix(".py").exists() else base / "__init__.py"
    if path not in _modules:
        text = path.read_text()
        lines = text.splitlines()
        _modules[path] = {n.name: lines[n.lineno - 1:n.end_lineno] for n in ast.walk(ast.parse(text))
                          if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
    defs = _modules[path]
    orig = func.rsplit("__mutmut_", 1)[0] + "__mutmut_orig"
    if func not in defs or orig not in defs:
        return "(not found in the mutated copy)"
    mutant = [l.replace(func, orig, 1) for l in defs[func]]
    return "\n".join(l for l in difflib.unified_diff(defs[orig], mutant, lineterm="", n=0)
                     if l.startswith(("+", "-")) and not l.startswith(("+++", "---")))


def classify(run):
    """[(mutant, kind)] of a run, kind one of killed, survived, no tests, not run."""
    out = []
    for name in run["sample"]:
        code = run["results"].get(name)
        out.append((name, "not run" if code is None else "killed" if code in KILLED else
                    "no tests" if code in NO_TESTS else "survived" if code in SURVIVED else "killed"))
    return out


def tally(run):
    per = defaultdict(lambda: {"killed": 0, "survived": 0, "no tests": 0, "not run": 0})
    tot = defaultdict(int)
    for name, kind in classify(run):
        per[area(name)][kind] += 1
        tot[kind] += 1
    return {l: per[l] for l in [*AREAS, "other"] if l in per}, tot


def reason(name, diff):
    """(class, reason) of a survivor from :data:`KNOWN`, or None when nobody read it yet."""
    func = name.rsplit("__mutmut_", 1)[0]
    changed = "\n".join(l[1:] for l in diff.splitlines() if l.startswith("+"))
    for k_func, needle, cls, why in KNOWN:
        # a needle "==text" matches only a changed text that is exactly ``text`` (stripped)
        hit = changed.strip() == needle[2:] if needle.startswith("==") else needle in changed
        if func == k_func and hit:
            return cls, why
    return None


def print_table(run):
    per, tot = tally(run)
    print(f"python mutation at commit {run['commit']}, seed {run['seed']}:")
    print(f"{'area':20} {'sample':>6} {'killed':>6} {'survived':>8} {'no tests':>8}  kill ratio")
    for label, c in per.items():
        n = sum(c.values())
        print(f"{label:20} {n:6} {c['killed']:6} {c['survived']:8} {c['no tests']:8}  "
              f"{100 * c['killed'] / n:.1f}%")
    n_all = sum(tot.values())
    print(f"{'all':20} {n_all:6} {tot['killed']:6} {tot['survived']:8} {tot['no tests']:8}  "
          f"{100 * tot['killed'] / max(1, n_all):.1f}%  ({run['seconds'] / 60:.1f} min wall, seed {run['seed']})")
    for name, kind in classify(run):
        if kind != "killed":
            r = reason(name, run["diffs"].get(name, ""))
            print(f"  {kind}: {name}: {run['diffs'].get(name, '')!r}"
                  + (f" [{r[0]}]" if r else " [not read yet]"))


def doc_section(run):
    """The Markdown of one run: how it was made, the table, every survivor with what it
    changes and why it is not killed (``KNOWN``)."""
    per, tot = tally(run)
    n_all = sum(tot.values())
    load = run.get("load")
    out = [f"Generated by `{run['command']}` at commit {run['commit']} (mutmut 3.8.1; "
           f"{run['generated']} mutants generated, a sample of {len(run['sample'])} drawn with seed "
           f"{run['seed']}, at least {run['min_area']} an area; {run['seconds'] / 60:.1f} min wall on the "
           f"2-core machine" + (f", load average {load[0]:.1f} at the end" if load else "") + ").", "",
           "Mutated: " + ", ".join(f"`{x}`" for x in run["mutated"]) + "; tests: "
           + ", ".join(f"`{x}`" for x in run["tests"]) + ".", "",
           "| area | sample | killed | survived | no test reaches it | kill ratio |",
           "|---|---|---|---|---|---|"]
    for label, c in per.items():
        n = sum(c.values())
        out.append(f"| `{label}` | {n} | {c['killed']} | {c['survived']} | {c['no tests']} | "
                   f"{100 * c['killed'] / n:.1f}% |")
    out.append(f"| all | {n_all} | {tot['killed']} | {tot['survived']} | {tot['no tests']} | "
               f"{100 * tot['killed'] / max(1, n_all):.1f}% |")
    if tot["not run"]:
        out += ["", f"{tot['not run']} mutant(s) of the sample did not run (counted as survivors)."]
    if run["deselected"]:
        out += ["", f"Left out: {len(run['deselected'])} selected test(s) that fail on commit "
                f"{run['commit']} itself (mutmut needs them green): "
                + ", ".join(f"`{d}`" for d in run["deselected"]) + "."]
    survivors = [(n, k) for n, k in classify(run) if k != "killed"]
    out += ["", "Survivors (mutant, what it changes, why no test of the selection kills it):", ""]
    by_class = defaultdict(int)
    for name, kind in survivors:
        diff = run["diffs"].get(name, "")
        r = reason(name, diff)
        cls, why = r if r else ("not read yet", "")
        by_class[cls] += 1
        d = " / ".join(l.strip() if l[0] not in "+-" else l[0] + " " + l[1:].strip()
                       for l in diff.splitlines()).replace("`", "'").replace("|", "\\|")
        out.append(f"* `{name}` ({kind}): `{d}` — **{cls}**" + (f": {why}" if why else ""))
    if not survivors:
        out.append("* none")
    else:
        eq = by_class.get("equivalent", 0)
        out += ["", "Survivors by reason: " + ", ".join(f"{v} {k}" for k, v in sorted(by_class.items()))
                + f". Without the equivalent ones the ratio is {tot['killed']} of {n_all - eq} "
                f"({100 * tot['killed'] / max(1, n_all - eq):.1f} %)."]
    return out


def write_doc(doc, runs):
    block = [BEGIN, ""]
    for i, run in enumerate(runs):
        if len(runs) > 1:
            block += [f"**Draw {i + 1} of {len(runs)}** (seed {run['seed']}, commit {run['commit']}).", ""]
        block += doc_section(run) + [""]
    block += ["The section between the markers is written by `pymut.py --doc` (or `--doc-from` "
              "with saved runs); a survivor's reason comes from `KNOWN` in tests/mutants/pymut.py, "
              "matched on its function and the changed line, so a reason written once holds for "
              "any later draw of the same mutant.", "", END]
    text = doc.read_text() if doc.exists() else ""
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        text = head + "\n".join(block) + rest.split(END, 1)[1]
    else:
        text += "\n" + "\n".join(block) + "\n"
    doc.write_text(text)


def main(argv=None):
    p = argparse.ArgumentParser(prog="python tests/mutants/pymut.py", description=__doc__.split("\n")[0])
    p.add_argument("--sample", type=int, default=100, help="mutants drawn (default 100)")
    p.add_argument("--seed", type=int, default=1, help="seed of the draw (default 1)")
    p.add_argument("--min-area", type=int, default=10,
                   help="mutants drawn from each area at least (default 10; the rest in proportion)")
    p.add_argument("-j", "--jobs", type=int, default=2, help="mutmut --max-children (default 2)")
    p.add_argument("--out", type=Path, default=ROOT / "build" / "pymut")
    p.add_argument("--doc", type=Path, default=None,
                   help="write the draw's section (table, every survivor with its diff and reason) "
                        "between pymut:begin and pymut:end of this file")
    p.add_argument("--doc-from", type=Path, action="append", default=None, metavar="RESULTS",
                   help="write --doc from saved runs (their pymut_results_seed*.json, in order; the "
                        "survivors' reasons as KNOWN says now) without running anything")
    p.add_argument("--commit", default="HEAD", help="the commit to mutate (default HEAD)")
    p.add_argument("--baseline", action="store_true",
                   help="a clean pytest run of the selection before mutmut's record (default: only "
                        "when the record fails, to name the failing tests and leave them out)")
    p.add_argument("--only", action="append", default=None, metavar="GLOB",
                   help="mutate only these files (bumprtl/<package>/... globs; default: all of MUTATE)")
    p.add_argument("--tests", action="append", default=None, metavar="PATH",
                   help="the tests mutmut selects from (default: TESTS)")
    p.add_argument("--deselect", action="append", default=[], metavar="NODEID",
                   help="leave this test out of the record and the runs (a test known to fail in "
                        "mutmut's copy; the runner finds such tests itself when the record fails, "
                        "at the cost of a run of the whole selection)")
    a = p.parse_args(argv)
    for name, value, lo in (("--sample", a.sample, 1), ("--jobs", a.jobs, 1), ("--min-area", a.min_area, 0)):
        if value < lo:
            print(f"error: {name} must be at least {lo}, got {value}", file=sys.stderr)
            return 2
    if a.doc_from:
        if not a.doc:
            print("error: --doc-from needs --doc", file=sys.stderr)
            return 2
        runs = [json.loads(f.read_text()) for f in a.doc_from]
        for run in runs:
            print_table(run)
        write_doc(a.doc, runs)
        return 0
    t0 = time.perf_counter()
    tree = a.out / "tree"
    a.out.mkdir(parents=True, exist_ok=True)
    log = a.out / "mutmut.log"
    log.write_text("")
    # bytecode is written: the mutated copy holds every mutant of every file (hundreds of MB
    # of source), and each process that imports it without .pyc files compiles all of it
    # again (a cocotb bench's simulator then took minutes and GBs of memory before its
    # first test, and the record failed on it)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONDONTWRITEBYTECODE")}
    head = subprocess.run(["git", "rev-parse", "--short", a.commit], cwd=ROOT, capture_output=True,
                          text=True, check=True).stdout.strip()
    stamp = tree / ".commit"
    if stamp.exists() and stamp.read_text() == head and (tree / "mutants").is_dir():
        commit = head                    # the same commit laid out before: mutmut reuses its mutants
    else:
        files, commit = committed_tree(a.out / "head", a.commit)
        if stamp.exists() and (tree / "mutants").is_dir():
            changed = update_tree(tree, a.out / "head", files)
            print(f"the copy of {stamp.read_text()} laid out again at {commit}: {len(changed)} "
                  f"file(s) changed, mutmut mutates only those again", flush=True)
        else:
            lay_out(tree, a.out / "head", files)
        stamp.write_text(commit)
    # 1. generate every mutant and record which tests reach each function; the name filter
    #    matches none, so no mutant runs yet (mutmut stops there with an error we expect).
    #    mutmut's own record runs every selected test, so a separate clean run first is needed
    #    only when a test fails there (its record is then missing): then the baseline names
    #    the failing tests, they are left out, and the record is made again
    deselect = list(a.deselect)
    if a.baseline:
        deselect += failing_tests(tree, env, log, a.tests, a.jobs)

    def record():
        configure(tree, deselect, a.only, a.tests)
        mutmut(["run", "--max-children", str(a.jobs), "bumprtl.no_such_module.x__mutmut_1"], tree, env, log)
        return all_results(tree) if (tree / "mutants" / "mutmut-stats.json").exists() else {}
    results = record()
    if not results and not a.baseline:
        # where mutmut ran them: its mutants/ copy, which holds only what mutmut copies
        # there, with the trampolines recording as in mutmut's record
        where = tree / "mutants" if (tree / "mutants").is_dir() else tree
        found = [t for t in failing_tests(where, env, log, a.tests, a.jobs, recording=where != tree)
                 if t not in deselect]
        deselect += found
        results = record() if found else {}
    if deselect:
        print(f"{len(deselect)} selected test(s) fail on commit {commit} itself and are left out: "
              + ", ".join(deselect))
    if not results:
        print(f"error: mutmut generated no mutants or no test statistics; see {log}", file=sys.stderr)
        return 1
    # only the mutants of the files mutated in this run (the tree may hold other files'
    # mutants from a wider run of the same commit)
    import fnmatch
    globs = a.only or MUTATE
    names = sorted(n for n in results
                   if any(fnmatch.fnmatch(n.rpartition(".")[0].replace(".", "/") + ".py", g)
                          or fnmatch.fnmatch(n.rpartition(".")[0].replace(".", "/") + "/__init__.py", g)
                          for g in globs))
    sample = draw(names, a.sample, a.seed, a.min_area)
    print(f"python mutation (mutmut 3.8.1) at commit {commit}: {len(names)} mutants generated, "
          f"a sample of {len(sample)} drawn with seed {a.seed} (at least {a.min_area} an area)")
    # 2. run exactly the sample, each against the tests that reach its function
    mutmut(["run", "--max-children", str(a.jobs), *sample], tree, env, log)
    results = all_results(tree)
    run = {"command": command_line(argv), "commit": commit, "seed": a.seed, "min_area": a.min_area,
           "generated": len(names), "sample": sample, "results": {k: results.get(k) for k in sample},
           "mutated": list(a.only or MUTATE), "tests": selected_tests(tree, a.tests),
           "deselected": deselect, "seconds": None, "load": os.getloadavg()}
    # what each survivor changes, read from mutmut's mutated copy (``mutmut show`` parses the
    # whole mutated module with libcst for each one: minutes a survivor on the big modules)
    run["diffs"] = {name: mutant_diff(tree, name) for name, kind in classify(run) if kind != "killed"}
    run["seconds"] = time.perf_counter() - t0
    (a.out / "pymut_results.json").write_text(json.dumps(run, indent=1))
    (a.out / f"pymut_results_seed{a.seed}_{commit}.json").write_text(json.dumps(run, indent=1))
    print_table(run)
    if a.doc:
        write_doc(a.doc, [run])
    per, tot = tally(run)
    if tot["not run"]:
        print(f"error: {tot['not run']} mutant(s) of the sample did not run (mutmut stopped "
              f"early: its fork server crashed?); see {log}", file=sys.stderr)
    return 0 if tot["killed"] >= 0.9 * sum(tot.values()) else 1

if __name__ == "__main__":
    sys.exit(main())
