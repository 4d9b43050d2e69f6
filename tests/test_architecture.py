"""The layering the architecture promises (docs/architecture.md): no import cycles among the
sweep modules, kernels/ free of the sweep layer and of I/O, and `import sweep` free of Numba."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _modules(folder: Path, package: str) -> dict[str, Path]:
    found = {}
    for path in sorted(folder.rglob("*.py")):
        parts = path.relative_to(folder).with_suffix("").parts
        name = ".".join((package,) + parts).removesuffix(".__init__")
        found[name] = path
    return found


def _imports(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """Every module of `known` that `name` imports, at module level or inside a function (a
    lazy import is still a dependency). `from . import x` counts as importing the submodule x,
    not the package being initialised."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            subs = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in known]
            names = subs if len(subs) == len(node.names) else [target, *subs]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        out |= {n for n in names if n in known and n != name}
    return out


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of `graph`, or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(v: str) -> list[str] | None:
        state[v] = 1
        path.append(v)
        for w in sorted(graph[v]):
            if state.get(w) == 1:
                return path[path.index(w):] + [w]
            if w not in state and (found := visit(w)):
                return found
        state[v] = 2
        path.pop()
        return None

    for v in sorted(graph):
        if v not in state and (found := visit(v)):
            return found
    return None


def test_the_sweep_modules_import_each_other_without_cycles():
    known = _modules(ROOT / "sweep", "sweep")
    graph = {name: _imports(name, path, known) for name, path in known.items()}
    assert _cycle(graph) is None, " -> ".join(_cycle(graph))
    # and the test can see a cycle: one added edge closes run -> runner -> run
    assert "sweep.runner" in graph["sweep.run"]
    graph["sweep.runner"].add("sweep.run")
    assert _cycle(graph) is not None


def test_kernels_import_neither_the_sweep_layer_nor_io():
    for path in sorted((ROOT / "kernels").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level
                     else [])
            for n in names:
                top = n.split(".")[0]
                assert top not in ("sweep", "xarray", "dask", "netCDF4", "matplotlib", "os",
                                   "pathlib", "io"), f"{path.name} imports {n}"


def test_importing_sweep_does_not_import_numba():
    """`import sweep` (and so `import sweep.errors`, the scene, dataset and model layers)
    imports no Numba: the kernels' layouts and state table are plain constants
    (kernels/layout.py, states.py, wave_layout.py); Numba is imported when a kernel runs."""
    code = ("import sys, sweep.errors, sweep, sweep.scene, sweep.dataset, sweep.models, "
            "sweep.models.transverse, sweep.models.longitudinal; "
            "print(sorted(m for m in sys.modules if m == 'numba' or m.startswith('numba.')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout


def _sweep_graph() -> dict[str, set[str]]:
    known = _modules(ROOT / "sweep", "sweep")
    known.update(_modules(ROOT / "kernels", "sweep.kernels"))
    return {name: _imports(name, path, known) for name, path in known.items()
            if not name.startswith("sweep.kernels")}


def test_the_layers_know_what_the_architecture_says_they_know():
    """docs/architecture.md sec. 1: the runner knows no physics (no model, no kernel); the
    execution layer holds each kernel family's chunk call but no model, except the stepped
    sweep's line solver (models/continuation.py); the models are the only sweep modules that
    read the Basis; scene/ takes its physics rules from the models (sweep.models.rules) and the
    models read Scenes: the two packages import each other, with no module cycle."""
    graph = _sweep_graph()
    models = {n for n in graph if n.startswith("sweep.models")}
    kernels = lambda deps: {d for d in deps if d.startswith("sweep.kernels")}  # noqa: E731
    assert not graph["sweep.runner"] & models and not kernels(graph["sweep.runner"])
    for layer in ("sweep.execute", "sweep.threads", "sweep.store", "sweep.dask_worker"):
        assert graph[layer] & models <= {"sweep.models.continuation"}, (layer, graph[layer])
    assert {n for n, deps in graph.items() if "sweep.models.basis" in deps} <= models
    # the checks see what they check: the execution layer does import the line solver
    assert "sweep.models.continuation" in graph["sweep.execute"]
    scene_uses = set().union(*(graph[n] for n in graph if n.startswith("sweep.scene")))
    assert "sweep.models.rules" in scene_uses
    assert any("sweep.scene" in graph[n] or any(d.startswith("sweep.scene.") for d in graph[n])
               for n in models)


# What every step of the scalar drivers calls: compiled without Numba's reference counting
# (atomic updates of every array argument's count at each call; with them the multi-mode
# scalar driver took 1.5x as long, benchmarks/RESULTS.md, twenty-ninth session). A kernel
# compiled so allocates nothing (Numba refuses to compile it otherwise) and must not hand an
# array it made to a caller that counts references (kernels.modes.member keeps them).
PER_STEP_UNCOUNTED = {
    "dopri5.py": ["rk_step", "error_norm", "step_factor"],
    "dop853.py": ["rk_step", "error_norm"],
    "oscillator.py": ["acceleration", "base_acceleration"],
    "modes.py": ["derivative", "lanes_derivative", "_polynomial_lanes", "_polynomial_mode",
                 "_energy_forces", "_lanes_fields", "prepare"],
    "modal_driver.py": ["rk_step", "error_norm", "_observe_modes", "restart_modes"],
    "trajectory.py": ["next_attempt", "control", "record_step"],
    "lanes.py": ["_attempt", "_attempt8"],
    "modal_lanes.py": ["_attempt", "_combine", "_control"],
}


def _decorator_keywords(tree: ast.Module) -> dict[str, dict[str, ast.expr]]:
    """{function name: its Numba decorator's keywords} of a module's top-level functions."""
    found = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            for deco in node.decorator_list:
                if isinstance(deco, ast.Call):
                    found[node.name] = {k.arg: k.value for k in deco.keywords}
    return found


def test_the_per_step_kernels_keep_no_reference_counts():
    for module, names in PER_STEP_UNCOUNTED.items():
        keywords = _decorator_keywords(ast.parse((ROOT / "kernels" / module).read_text()))
        for name in names:
            flag = keywords[name].get("_nrt")
            assert isinstance(flag, ast.Constant) and flag.value is False, (
                f"kernels/{module}: {name} is compiled with reference counting")


LLVM_INLINED = ["lanes_derivative", "_polynomial_lanes", "_polynomial_mode", "_lanes_fields",
                "_energy_forces", "_energy_only_forces", "_eq17_forces", "_pair_forces",
                "_lanes_signal", "_lanes_sine"]


def _calls_of(function: ast.FunctionDef, name: str) -> int:
    """How many calls of `name` (plain or an attribute) a function's body makes."""
    return sum(1 for node in ast.walk(function) if isinstance(node, ast.Call)
               and getattr(node.func, "attr", getattr(node.func, "id", None)) == name)


def test_the_lanes_right_hand_side_is_inlined_by_llvm_from_one_call_site():
    """docs/architecture.md: the multi-mode lanes' right-hand side and its helpers are compiled
    forceinline (no call passing ~100 words of array structs 6-12 times an attempt), and
    modal_lanes._attempt calls it from one site (each site is one more inlined copy to
    compile)."""
    keywords = _decorator_keywords(ast.parse((ROOT / "kernels" / "modes.py").read_text()))
    for name in LLVM_INLINED:
        flag = keywords[name].get("forceinline")
        assert isinstance(flag, ast.Constant) and flag.value is True, (
            f"kernels/modes.py: {name} is not compiled forceinline")
    tree = ast.parse((ROOT / "kernels" / "modal_lanes.py").read_text())
    attempt = next(node for node in tree.body
                   if isinstance(node, ast.FunctionDef) and node.name == "_attempt")
    assert _calls_of(attempt, "lanes_derivative") == 1


def test_the_tests_leave_the_sweep_under_test_first_on_the_path():
    """What this process spawns imports the sweep it imported: a dask worker starts with this
    process's sys.path, and a checkout put before an installed sweep there (a test module
    inserting the repository's root at import) made CI's dask workers compile every kernel
    again into the checkout's own Numba cache (95 cache indexes, minutes of CI). Every test
    module is imported before any test runs, so this sees what they all left."""
    from conftest import SWEEP_ROOT
    first = next((Path(entry or ".").resolve() for entry in sys.path
                  if (Path(entry or ".") / "sweep" / "__init__.py").is_file()), SWEEP_ROOT)
    assert first == SWEEP_ROOT, (first, SWEEP_ROOT)


class _KernelCalls:
    """Which compiled kernel functions each kernel function calls, read from the source: by
    name in its module, through `from . import x as y` and `from .x import f`, and through the
    functions that choose a callee as they compile (an `@overload`'s body, `by_kind`)."""

    def __init__(self) -> None:
        self.trees = {p.stem: ast.parse(p.read_text()) for p in (ROOT / "kernels").glob("*.py")}
        self.keywords, self.chooses, self.bodies = {}, {}, {}
        self.aliases = {m: {} for m in self.trees}
        for module, tree in self.trees.items():
            for node in tree.body:
                if isinstance(node, ast.ImportFrom) and node.level == 1:
                    for a in node.names:
                        self.aliases[module][a.asname or a.name] = (
                            (a.name, None) if node.module is None else (node.module, a.name))
                elif isinstance(node, ast.FunctionDef):
                    for deco in node.decorator_list:
                        if not isinstance(deco, ast.Call):
                            continue
                        if "jit" in ast.unparse(deco.func):
                            self.keywords[module, node.name] = {k.arg: k.value
                                                                for k in deco.keywords}
                            self.bodies[module, node.name] = node
                        elif ast.unparse(deco.func) == "overload":
                            self.chooses[module, ast.unparse(deco.args[0])] = (module, [node])
                elif (isinstance(node, ast.Assign) and isinstance(node.value, ast.Call)
                      and ast.unparse(node.value.func).endswith("by_kind")):
                    self.chooses[module, node.targets[0].id] = (module, node.value.args)

    def _named(self, module: str, expr: ast.expr) -> tuple[str, str] | None:
        if isinstance(expr, ast.Attribute) and isinstance(expr.value, ast.Name):
            target = self.aliases[module].get(expr.value.id)
            return (target[0], expr.attr) if target and target[1] is None else None
        if isinstance(expr, ast.Name):
            target = self.aliases[module].get(expr.id)
            return target if target and target[1] is not None else (module, expr.id)
        return None

    def callees(self, module: str, node: ast.AST, seen: frozenset = frozenset()) -> set:
        found = set()
        for call in (n for n in ast.walk(node) if isinstance(n, ast.Call)):
            key = self._named(module, call.func)
            if key in self.keywords:
                found.add(key)
            elif key in self.chooses and key not in seen:
                where, choices = self.chooses[key]
                for choice in choices:
                    named = self._named(where, choice) if isinstance(choice, ast.Name) else None
                    if named in self.keywords:
                        found.add(named)
                    elif not isinstance(choice, ast.Name):
                        found |= self.callees(where, choice, seen | {key})
        return found


def test_a_contracting_kernel_calls_only_kernels_that_state_their_fastmath():
    """Numba compiles a function that sets no `fastmath` with the flags of the first caller
    that compiles it, and every later caller of the same types reuses that compile (from the
    cache too). Called both from a kernel that lets a * b + c fuse (fastmath={"contract"}) and
    from one that does not (or from Python), such a function's last bits depended on what had
    been compiled before: after the test suite had filled the cache, two 3-mode random runs
    differed in 85 values (of 356 in ten multi-mode runs; docs/architecture.md,
    benchmarks/RESULTS.md). So a kernel compiled with contraction calls only kernels that
    state their own fastmath (or are inlined into it as Numba IR, inline="always"), and every
    kernel that sets none is compiled without it."""
    calls = _KernelCalls()
    wrong = []
    for key, keywords in calls.keywords.items():
        flag = keywords.get("fastmath")
        if flag is None or (isinstance(flag, ast.Constant) and not flag.value):
            continue
        todo, seen = [key], {key}
        while todo:         # what it calls, and what the callees it inlines as IR call
            caller = todo.pop()
            for callee in calls.callees(caller[0], calls.bodies[caller]) - seen:
                seen.add(callee)
                inline = calls.keywords[callee].get("inline")
                if inline is not None and not (isinstance(inline, ast.Constant)
                                               and inline.value == "never"):
                    todo.append(callee)    # "always", or InlineWhereTrue: inlined somewhere
                if "fastmath" not in calls.keywords[callee] and not (
                        isinstance(inline, ast.Constant) and inline.value == "always"):
                    wrong.append(f"kernels/{key[0]}.py: {key[1]} calls "
                                 f"{callee[0]}.{callee[1]}")
    # the check sees through the choosers: modes._lanes_signal reads a record through
    # excitation.signal's overload, and modal_lanes reaches its record hooks through by_kind
    assert ("excitation", "record_acceleration") in calls.callees(
        "modes", calls.bodies["modes", "_lanes_signal"])
    assert ("modal_lanes", "_record_steps") in calls.callees(
        "modal_lanes", calls.bodies["modal_lanes", "solve_block"])
    assert not wrong, "\n".join(["set fastmath on the callee:"] + sorted(wrong))
