"""The import graph of rtl/, sim/ and gen/, read from the source with ``ast``:

(a) every import sits at the top of its module: none inside a function or method body,
    except a line marked ``# optional dependency`` (a package the code runs without);
(b) no import cycle among the bumprtl modules (module-level imports; ``from bumprtl.x
    import y`` counts as importing ``bumprtl.x.y`` when that is a module, and importing a
    module also runs its packages' ``__init__``);
(c) the layers point one way, lowest first: rtl/, gen/tools/ (running the external tools),
    sim/, the rest of gen/; a module imports its own layer and those below it only
    (function-level imports and ``importlib.import_module("bumprtl.gen...")`` included);
(d) no function or class of rtl/ has a parameter (a dataclass field included) whose
    annotation or default names a type of sim/ or gen/: names resolved through the module's
    imports, string annotations parsed, and a bare name in a string that is not imported
    matched against the classes sim/ and gen/ define.

Each check names the offending module, file and line. The ``*_is_caught`` tests run the
same checks on a small package with one planted offence each, so every check is shown to
fail when it should.
"""

import ast
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAYERS = ("rtl", "sim", "gen")          # the folders checked, as mapped in pyproject.toml
OPTIONAL = "# optional dependency"
FUNCTIONS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)


def package_dirs(root=ROOT):
    """``{"bumprtl.rtl": root / "rtl", ...}`` from pyproject's [tool.setuptools.package-dir]."""
    with open(root / "pyproject.toml", "rb") as f:
        mapping = tomllib.load(f)["tool"]["setuptools"]["package-dir"]
    return {pkg: root / d for pkg, d in mapping.items() if d in LAYERS}


def modules(dirs):
    """``{dotted module name: (path, ast tree, source lines)}`` of every .py file."""
    out = {}
    for pkg, folder in dirs.items():
        for path in sorted(folder.rglob("*.py")):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            text = path.read_text()
            out[".".join([pkg, *parts])] = (path, ast.parse(text, str(path)), text.splitlines())
    return out


def imports(tree):
    """``(node, function name or None)`` for every import statement of ``tree``."""
    found = []

    def visit(node, func):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                found.append((child, func))
            inner = (getattr(child, "name", "<lambda>") if isinstance(child, FUNCTIONS) else func)
            visit(child, inner)

    visit(tree, None)
    return found


def targets(node, name, path, mods):
    """The bumprtl modules an import statement of module ``name`` (file ``path``) loads."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    base = node.module or ""
    if node.level:                                    # relative: from the package of ``name``
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        package = package[:len(package) - node.level + 1]
        base = ".".join(package + ([node.module] if node.module else []))
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]


def _where(path, node, root):
    return f"{path.relative_to(root)}:{node.lineno}"


def function_level_imports(mods, root=ROOT):
    """Lines ``file:line in func(): statement`` of imports inside a function body."""
    bad = []
    for _name, (path, tree, lines) in mods.items():
        for node, func in imports(tree):
            text = lines[node.lineno - 1:node.end_lineno]
            if func is None or any(OPTIONAL in ln for ln in text):
                continue
            bad.append(f"{_where(path, node, root)} in {func}(): {ast.unparse(node)}")
    return bad


def import_graph(mods):
    """``{module: {imported module: first line}}`` of the module-level imports."""
    graph = {name: {} for name in mods}
    for name, (path, tree, _) in mods.items():
        own = {".".join(name.split(".")[:i]) for i in range(1, name.count(".") + 2)}
        for node, func in imports(tree):
            if func is not None:
                continue
            for target in targets(node, name, path, mods):
                parts = target.split(".")
                # the target and the packages whose __init__ it runs (not our own packages,
                # which are already being imported when this module runs)
                for i in range(2, len(parts) + 1):
                    dep = ".".join(parts[:i])
                    if dep in mods and dep not in own:
                        graph[name].setdefault(dep, node.lineno)
    return graph


def cycles(graph):
    """One cycle (a list of modules, first == last) per strongly connected component."""
    index, low, stack, on_stack, comps = {}, {}, [], set(), []

    def connect(v):                                  # Tarjan; the graph is small
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(comp)

    for v in sorted(graph):
        if v not in index:
            connect(v)
    out = []
    for comp in comps:                               # shortest way back to the first module
        start = min(comp)
        paths, seen = [[start]], {start}
        while paths:
            path = paths.pop(0)
            nxt = sorted(w for w in graph[path[-1]] if w in comp)
            if start in nxt:
                out.append(path + [start])
                break
            for w in nxt:
                if w not in seen:
                    seen.add(w)
                    paths.append(path + [w])
    return out


def describe_cycle(cycle, graph, mods, root=ROOT):
    steps = [f"{a} ({mods[a][0].relative_to(root)}:{graph[a][b]})" for a, b in zip(cycle, cycle[1:], strict=False)]
    return " -> ".join(steps + [cycle[-1]])


def _dynamic_imports(tree):
    """``(node, module string)`` of ``import_module("...")`` / ``__import__("...")`` calls."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and node.args:
            func = node.func
            fname = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            arg = node.args[0]
            if isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
                arg = arg.values[0]
            if fname in ("import_module", "__import__") and isinstance(arg, ast.Constant) \
                    and isinstance(arg.value, str):
                yield node, arg.value


# The layers point one way, lowest first: rtl/ (the hardware) imports nothing above it;
# gen/tools/ (the toolchain lookup, job layer, Yosys runner, page sections) imports only
# rtl/; sim/ (models, testbenches, formal) imports rtl/ and gen/tools/ but no other gen/;
# the rest of gen/ imports all of them. A module's layer is the longest prefix it has.
ORDER = ("bumprtl.rtl", "bumprtl.gen.tools", "bumprtl.sim", "bumprtl.gen")


def _layer(name):
    found = [n for n, layer in enumerate(ORDER) if name == layer or name.startswith(layer + ".")]
    return max(found, key=lambda n: len(ORDER[n])) if found else None


def _forbidden(name, target):
    mine, theirs = _layer(name), _layer(target)
    return mine is not None and theirs is not None and theirs > mine


def wrong_way_imports(mods, root=ROOT):
    """Lines where a module imports a layer above its own (:data:`ORDER`): rtl imports
    bumprtl.sim or bumprtl.gen, gen/tools imports bumprtl.sim or the rest of bumprtl.gen,
    sim imports bumprtl.gen outside gen/tools."""
    bad = []
    for name, (path, tree, _) in mods.items():
        for node, _ in imports(tree):
            for target in targets(node, name, path, mods):
                line = f"{name} ({_where(path, node, root)}) imports {target}"
                if _forbidden(name, target) and line not in bad:
                    bad.append(line)
        for node, target in _dynamic_imports(tree):
            if _forbidden(name, target.rstrip(".")) or _forbidden(name, target):
                bad.append(f"{name} ({_where(path, node, root)}) imports {target} dynamically")
    return bad


def _import_names(tree):
    """``{local name: dotted name}`` of the module-level imports of ``tree`` (absolute)."""
    names = {}
    for node, func in imports(tree):
        if func is not None:
            continue
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.asname:
                    names[a.asname] = a.name
                else:
                    names[a.name.split(".")[0]] = a.name.split(".")[0]
        elif not node.level:
            for a in node.names:
                names[a.asname or a.name] = f"{node.module}.{a.name}"
    return names


def _upper_classes(mods):
    """``{class name: dotted name}`` of the classes sim/ and gen/ define at module level."""
    return {n.name: f"{name}.{n.name}" for name, (_, tree, _) in mods.items()
            if _layer(name) is not None and _layer(name) > 0
            for n in tree.body if isinstance(n, ast.ClassDef)}


def _named_types(expr, names, upper, local):
    """The dotted names of sim/ or gen/ that annotation or default ``expr`` mentions."""
    found, todo = [], [expr]
    while todo:
        node = todo.pop(0)
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            try:
                inner = ast.parse(node.value, mode="eval").body
            except SyntaxError:
                continue
            found += _named_types(inner, names, upper, local)
            for n in ast.walk(inner):       # a bare name no import brings: a class above?
                if isinstance(n, ast.Name) and n.id not in names and n.id not in local \
                        and n.id in upper:
                    found.append(upper[n.id])
            continue
        parts, head = [], node
        while isinstance(head, ast.Attribute):        # a dotted name: resolved as a whole
            parts.insert(0, head.attr)
            head = head.value
        if isinstance(head, ast.Name):
            dotted = ".".join([names.get(head.id, ""), *parts])
            if head.id in names and (_layer(dotted) or 0) > 0:
                found.append(dotted)
            continue
        todo.extend(ast.iter_child_nodes(node))
    return found


def _parameters(tree):
    """``(owner, parameter, annotation or default)`` of every function and class of ``tree``:
    the arguments of functions and lambdas, the annotated fields of class bodies."""
    out = []

    def visit(node, owner):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, FUNCTIONS):
                name = f"{owner}.{getattr(child, 'name', '<lambda>')}".lstrip(".")
                a = child.args
                params = [*a.posonlyargs, *a.args, *a.kwonlyargs,
                          *([a.vararg] if a.vararg else []), *([a.kwarg] if a.kwarg else [])]
                out.extend((child, name, p.arg, p.annotation) for p in params if p.annotation)
                positional = [*a.posonlyargs, *a.args]
                out.extend((child, name, p.arg, d) for p, d in
                           zip(positional[len(positional) - len(a.defaults):], a.defaults, strict=True))
                out.extend((child, name, p.arg, d) for p, d in zip(a.kwonlyargs, a.kw_defaults, strict=True)
                           if d is not None)
                visit(child, name)
            elif isinstance(child, ast.ClassDef):
                name = f"{owner}.{child.name}".lstrip(".")
                for field in child.body:
                    if isinstance(field, ast.AnnAssign) and isinstance(field.target, ast.Name):
                        out.append((field, name, field.target.id, field.annotation))
                        if field.value is not None:
                            out.append((field, name, field.target.id, field.value))
                visit(child, name)
            else:
                visit(child, owner)

    visit(tree, "")
    return out


def upper_typed_parameters(mods, root=ROOT):
    """Lines ``file:line owner(parameter): dotted name`` where a function or class of rtl/
    has a parameter annotated with (or defaulting to) a type of sim/ or gen/."""
    upper, bad = _upper_classes(mods), []
    for name, (path, tree, _) in mods.items():
        if _layer(name) != 0:
            continue
        names = _import_names(tree)
        local = {n.name for n in ast.walk(tree) if isinstance(n, (ast.ClassDef, *FUNCTIONS[:2]))}
        for node, owner, param, expr in _parameters(tree):
            for dotted in _named_types(expr, names, upper, local):
                line = f"{_where(path, node, root)} {owner}({param}): {dotted}"
                if line not in bad:
                    bad.append(line)
    return bad


MODULES = modules(package_dirs())


def test_the_checked_tree_is_the_package():
    names = set(MODULES)
    assert {"bumprtl.rtl.config", "bumprtl.sim.golden.fixed.exact", "bumprtl.gen.cli.main"} <= names


def test_no_import_inside_a_function():
    bad = function_level_imports(MODULES)
    assert not bad, (f"{len(bad)} imports inside functions (move them to the module top; an "
                     f"optional dependency says so with '{OPTIONAL}'):\n  " + "\n  ".join(bad))


def test_no_import_cycle():
    graph = import_graph(MODULES)
    found = [describe_cycle(c, graph, MODULES) for c in cycles(graph)]
    assert not found, "import cycles:\n  " + "\n  ".join(found)


def test_layers_point_one_way():
    bad = wrong_way_imports(MODULES)
    assert not bad, ("rtl/ must not depend on sim/ or gen/, gen/tools/ not on sim/ or the rest of "
                     "gen/, sim/ not on gen/ outside gen/tools/:\n  "
                     + "\n  ".join(bad))


def test_no_rtl_parameter_takes_a_type_from_above():
    bad = upper_typed_parameters(MODULES)
    assert not bad, ("rtl/ functions and classes must not take a sim/ or gen/ type (the hardware "
                     "takes rtl types, e.g. rtl/scene.HardwareScene):\n  " + "\n  ".join(bad))


def test_the_scene_units_take_the_hardware_scene():
    """BumpPipeline's and BumpMapFetch's ``scene`` is annotated with the rtl type."""
    found = {(owner, param): ast.unparse(expr) for name in ("bumprtl.rtl.pipeline", "bumprtl.rtl.bumpfetch")
             for node, owner, param, expr in _parameters(MODULES[name][1])}
    assert found[("BumpPipeline.__init__", "scene")] == "HardwareScene"
    assert found[("BumpMapFetch.__init__", "scene")] == "HardwareScene"
    assert _import_names(MODULES["bumprtl.rtl.pipeline"][1])["HardwareScene"] == \
        "bumprtl.rtl.scene.HardwareScene"


# ---- the checks fail when they should -----------------------------------------------

def _tree(tmp_path, files):
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "pyproject.toml").write_text(
        '[tool.setuptools.package-dir]\n"bumprtl.rtl" = "rtl"\n"bumprtl.sim" = "sim"\n'
        '"bumprtl.gen" = "gen"\n')
    for rel, text in {"rtl/__init__.py": "", "sim/__init__.py": "", "gen/__init__.py": "",
                      **files}.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    return modules(package_dirs(tmp_path))


def test_a_function_level_import_is_caught(tmp_path):
    mods = _tree(tmp_path, {
        "rtl/a.py": "import os\n\n\ndef f():\n    import json\n    return json\n",
        "rtl/b.py": "class C:\n    def m(self):\n        from bumprtl.rtl import a\n",
        "rtl/c.py": "def g():\n    import yaml   # optional dependency: only for --yaml\n"})
    assert function_level_imports(mods, tmp_path) == [
        "rtl/a.py:5 in f(): import json", "rtl/b.py:3 in m(): from bumprtl.rtl import a"]


def test_a_cycle_is_caught(tmp_path):
    mods = _tree(tmp_path, {
        "gen/flow/__init__.py": "", "gen/report/__init__.py": "",
        "gen/flow/fpga.py": "from bumprtl.gen.report.table1 import TABLE1_ORDER\n",
        "gen/report/table1.py": "\nfrom bumprtl.gen.flow import fpga\n",
        "sim/x.py": "from bumprtl.sim import y\n", "sim/y.py": "import os\n"})
    graph = import_graph(mods)
    assert [describe_cycle(c, graph, mods, tmp_path) for c in cycles(graph)] == [
        "bumprtl.gen.flow.fpga (gen/flow/fpga.py:1) -> "
        "bumprtl.gen.report.table1 (gen/report/table1.py:2) -> bumprtl.gen.flow.fpga"]
    # a package __init__ that imports its own submodule is not a cycle
    mods = _tree(tmp_path / "init", {"sim/scenes/__init__.py": "from bumprtl.sim.scenes.h import f\n",
                                     "sim/scenes/h.py": "from bumprtl.sim.y import z\n",
                                     "sim/y.py": "z = 1\n"})
    assert cycles(import_graph(mods)) == []


def test_a_wrong_way_import_is_caught(tmp_path):
    mods = _tree(tmp_path, {
        "gen/flow/__init__.py": "", "gen/flow/emit.py": "from bumprtl.rtl import a\n",
        "rtl/a.py": "import os\n",
        "sim/stress.py": "import importlib\n\n\ndef f():\n    from bumprtl.gen.flow.emit import x\n"
                         "    return importlib.import_module(f'bumprtl.gen.flow.{x}')\n",
        "sim/tb/runner.py": "from bumprtl.gen.flow import emit\n"})
    assert wrong_way_imports(mods, tmp_path) == [
        "bumprtl.sim.stress (sim/stress.py:5) imports bumprtl.gen.flow.emit",
        "bumprtl.sim.stress (sim/stress.py:6) imports bumprtl.gen.flow. dynamically",
        "bumprtl.sim.tb.runner (sim/tb/runner.py:1) imports bumprtl.gen.flow.emit"]


def test_the_tool_layer_importing_above_it_is_caught(tmp_path):
    """gen/tools sits below sim: sim may import it, it may import rtl, but it importing sim
    or the rest of gen (or rtl importing it) is an offence."""
    mods = _tree(tmp_path, {
        "gen/tools/__init__.py": "", "gen/tools/yosys.py": "from bumprtl.rtl import a\n",
        "gen/tools/jobs.py": "from bumprtl.sim.golden import b\nfrom bumprtl.gen.flow import emit\n",
        "gen/flow/__init__.py": "", "gen/flow/emit.py": "from bumprtl.gen.tools import yosys\n",
        "rtl/a.py": "from bumprtl.gen.tools import jobs\n",
        "sim/golden.py": "from bumprtl.gen.tools import yosys\nfrom bumprtl.gen import flow\n"})
    assert sorted(wrong_way_imports(mods, tmp_path)) == [
        "bumprtl.gen.tools.jobs (gen/tools/jobs.py:1) imports bumprtl.sim.golden",
        "bumprtl.gen.tools.jobs (gen/tools/jobs.py:2) imports bumprtl.gen.flow.emit",
        "bumprtl.rtl.a (rtl/a.py:1) imports bumprtl.gen.tools.jobs",
        "bumprtl.sim.golden (sim/golden.py:2) imports bumprtl.gen.flow"]


def test_rtl_importing_sim_is_caught(tmp_path):
    """The hardware layer importing a golden model or a scene generator, statically, inside
    a function or by name, is an offence; sim importing rtl is the allowed direction."""
    mods = _tree(tmp_path, {
        "rtl/methods.py": "from bumprtl.sim.golden.fixed import exact\n",
        "rtl/scene.py": "import importlib\n\n\ndef f():\n    from bumprtl.sim import scenes\n"
                        "    return importlib.import_module('bumprtl.sim.scenes.usermap')\n",
        "sim/golden.py": "from bumprtl.rtl import methods\n"})
    assert wrong_way_imports(mods, tmp_path) == [
        "bumprtl.rtl.methods (rtl/methods.py:1) imports bumprtl.sim.golden.fixed",
        "bumprtl.rtl.scene (rtl/scene.py:5) imports bumprtl.sim",
        "bumprtl.rtl.scene (rtl/scene.py:6) imports bumprtl.sim.scenes.usermap dynamically"]


def test_an_rtl_parameter_typed_from_above_is_caught(tmp_path):
    """An annotation (plain, dotted, string, inside a union), a default, or a dataclass
    field naming a sim/ or gen/ type is an offence; rtl types and sim's own are not."""
    mods = _tree(tmp_path, {
        "sim/scenes/__init__.py": "",
        "sim/scenes/config.py": "class SceneConfig:\n    pass\n",
        "gen/flow/__init__.py": "", "gen/flow/emit.py": "class Job:\n    pass\n",
        "rtl/scene.py": "class HardwareScene:\n    pass\n",
        "rtl/a.py": "from bumprtl.sim.scenes.config import SceneConfig\n"
                    "import bumprtl.gen.flow.emit as emit\n"
                    "from bumprtl.rtl.scene import HardwareScene\n\n\n"
                    "class Top:\n"
                    "    def __init__(self, scene: SceneConfig, ok: HardwareScene, *, job=emit.Job):\n"
                    "        pass\n\n\n"
                    "def f(x: 'SceneConfig | None' = None, y: list[HardwareScene] = ()):\n"
                    "    return x, y\n",
        "rtl/b.py": "from dataclasses import dataclass\n\n\n@dataclass\n"
                    "class Holder:\n    scene: 'SceneConfig'\n    n: int = 1\n",
        "sim/c.py": "from bumprtl.sim.scenes.config import SceneConfig\n\n\n"
                    "def g(s: SceneConfig):\n    return s\n"})
    assert upper_typed_parameters(mods, tmp_path) == [
        "rtl/a.py:7 Top.__init__(scene): bumprtl.sim.scenes.config.SceneConfig",
        "rtl/a.py:7 Top.__init__(job): bumprtl.gen.flow.emit.Job",
        "rtl/a.py:11 f(x): bumprtl.sim.scenes.config.SceneConfig",
        "rtl/b.py:6 Holder(scene): bumprtl.sim.scenes.config.SceneConfig"]
