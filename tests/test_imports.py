"""The house's layering, read from the source: no import circles and no private imports.

Every import counts, those inside functions too (an import moved into a
function to break a circle still is one). ``from package import Name`` is
followed to the module the package's ``__init__`` takes ``Name`` from, so a
package's face re-exporting its modules is not itself a circle.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("pcabench", "solvers", "benchmarks")


def _modules() -> dict[str, Path]:
    """Dotted module name -> file, for every module of the house's packages."""
    out = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


MODULES = _modules()


def _is_package(name: str) -> bool:
    return MODULES[name].name == "__init__.py"


def _base(module: str, node: ast.ImportFrom) -> str:
    """The absolute name a ``from ... import`` statement in ``module`` imports from."""
    if not node.level:
        return node.module or ""
    parts = module.split(".")
    if not _is_package(module):
        parts = parts[:-1]
    parts = parts[: len(parts) - (node.level - 1)]
    return ".".join(parts + ([node.module] if node.module else []))


def _face(package: str) -> dict[str, str]:
    """What a package's ``__init__`` re-exports: name -> the module it comes from."""
    out = {}
    for node in ast.walk(ast.parse(MODULES[package].read_text())):
        if isinstance(node, ast.ImportFrom):
            base = _base(package, node)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                out[alias.asname or alias.name] = sub if sub in MODULES else base
    return out


def _target(base: str, name: str, seen=()) -> str | None:
    """The house module that ``from base import name`` reads, or None outside the house."""
    if f"{base}.{name}" in MODULES:
        return f"{base}.{name}"
    if base not in MODULES:
        return None
    if _is_package(base) and base not in seen:
        source = _face(base).get(name)
        if source and source != base:
            return _target(*source.rsplit(".", 1), seen=(*seen, base)) if source not in MODULES else source
    return base


def _imports(module: str):
    """(line, imported module, private names) for every import of ``module``'s file, at any depth."""
    for node in ast.walk(ast.parse(MODULES[module].read_text())):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in MODULES:
                    yield node.lineno, alias.name, ()
        elif isinstance(node, ast.ImportFrom):
            base = _base(module, node)
            for alias in node.names:
                target = _target(base, alias.name)
                if target is not None:
                    private = alias.name.startswith("_") and not alias.name.startswith("__")
                    yield node.lineno, target, (alias.name,) if private else ()


def _faces(module: str, target: str) -> list[str]:
    """The package faces importing ``target`` runs (``pcabench.store`` for ``pcabench.store.rows``), but for
    ``module``'s own packages, which ran before it: an import of a submodule is an import of its packages too."""
    parts = target.split(".")
    above = [".".join(parts[:i]) for i in range(1, len(parts))]
    return [a for a in above if a in MODULES and not (module == a or module.startswith(a + "."))]


GRAPH = {m: sorted({u for _, t, _ in _imports(m) if t != m for u in (t, *_faces(m, t)) if u != m}) for m in MODULES}


def _circles(graph) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each a circle of imports."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_the_graph_is_read():
    """The walk sees the imports it must: inside functions, relative, and through a package's face."""
    assert "solvers.scene" in GRAPH["pcabench.studies.preset"]  # `from solvers import Scene`, through the face
    assert "pcabench.studies.preset" in GRAPH["pcabench.cli.study"]  # imported inside a function
    # `from pcabench.store.rows import latest` runs the face pcabench.store first: an edge to it too
    assert {"pcabench.store.rows", "pcabench.store"} <= set(GRAPH["pcabench.studies.paper.rows"])
    assert len(GRAPH) > 50 and sum(map(len, GRAPH.values())) > 150


def test_a_circle_through_a_package_face_is_found():
    """A face that imports its build closes a circle with a module the build imports that imports the face's
    toolkit (what pcabench/reports/__init__.py did: a study -> pcabench.reports -> build -> the study)."""
    graph = {"pkg": ["pkg.build"], "pkg.build": ["study"], "study": ["pkg.tool", *_faces_of("study", "pkg.tool")]}
    graph["pkg.tool"] = []
    assert _circles(graph) == [["pkg", "pkg.build", "study"]]


def _faces_of(module: str, target: str) -> list[str]:
    """:func:`_faces` over a toy house of the packages named in ``target``."""
    parts = target.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts)) if not module.startswith(".".join(parts[:i]))]


def test_a_circle_is_found():
    assert _circles({"a": ["b"], "b": ["c"], "c": ["a"], "d": ["a"]}) == [["a", "b", "c"]]


def test_no_import_circles():
    assert _circles(GRAPH) == []


def test_solvers_never_import_the_harness():
    """The data flow runs one way: scenes and solvers know nothing of the harness that times and stores them."""
    back = [(m, t) for m, ts in GRAPH.items() if m.startswith("solvers") for t in ts if t.startswith("pcabench")]
    assert back == []


def test_no_private_imports():
    """No module reaches into another module's private (_underscore) names."""
    found = [
        f"{MODULES[m].relative_to(ROOT)}:{line} imports {', '.join(names)} from {t}"
        for m in MODULES
        for line, t, names in _imports(m)
        if names and t != m
    ]
    assert found == []


# The layers of the house, lowest first: a module imports from its own layer or one below, never one above (the
# data flow of ARCHITECTURE.md: scene -> solver -> stage clock -> run record -> store -> reports). A module's
# layer is that of the longest prefix here that names it.
LAYERS = (
    (
        "solvers.plugins",
        "solvers.kernels",
        "solvers.boundaries.absorbers",
        "solvers.corrections",
        "solvers.boundaries.bodies",
        "solvers.boundaries",
        "solvers.sampling",
        "solvers.jitcache",
        "solvers.sources",
        "solvers.fields",
    ),  # registries, kernels, absorbers, corrections, boundary methods, sampling between particles, a run's fields
    ("solvers.physics",),  # the rates per pair and the integrators, for every backend
    (
        "solvers.scene",
        "solvers.scenes",
        "solvers.interface",
        "solvers.reference",
        "solvers.method",
        "solvers.edges",
        "solvers.body",
    ),
    ("solvers.search", "solvers.gpu", "solvers.loops"),  # the neighbour search, the GPU backend, compiled loops
    ("solvers.allpair_cpu", "solvers.linkedlist_cpu", "solvers.linkedlist_gpu", "solvers.registry"),  # solvers
    ("solvers",),  # the package's face
    ("pcabench", "pcabench.errors", "pcabench.paths", "pcabench.jsonout", "pcabench.parameters", "pcabench.usage"),
    ("pcabench.spec", "pcabench.commands"),  # what one run is, and the command that makes it again
    ("pcabench.store",),  # the run record, its schema and the results store
    ("pcabench.machine",),  # this machine's profile and memory
    ("pcabench.predict",),  # wall time, stability and the fastest methods, predicted
    ("pcabench.execute",),  # the stage clock, a run, its child, the sweep
    # what every solver must do; what a preset is, and each study's plan (pcabench/studies/<study>/plan.py)
    # (a study's face, ``pcabench.studies.<study>``, runs before its plan: it sits with it, importing nothing)
    ("pcabench.conformance", "pcabench.studies", "pcabench.studies.*", "pcabench.studies.*.plan"),
    # the report's frame, tables and figure toolkit; each study's sections and what they draw (every other module
    # of a study's folder)
    ("pcabench.reports", "pcabench.studies.*.*"),
    ("pcabench.gpu", "pcabench.studies.*.gpu"),  # the GPU check, and each study's stage of it
    ("pcabench.cli", "pcabench.console"),  # the command line, and the console script that imports it
)


def _names(module: str, pattern: str) -> bool:
    """Whether ``pattern`` (a dotted prefix; ``*`` stands for one name: ``pcabench.studies.*.plan``) names
    ``module`` or a package above it."""
    parts, want = module.split("."), pattern.split(".")
    return len(parts) >= len(want) and all(w in ("*", p) for w, p in zip(want, parts))


def layer_of(module: str) -> int | None:
    """The layer of the most specific pattern that names ``module``: the most names, then the fewest ``*``."""
    best = max(
        ((len(p.split(".")), -p.count("*"), i) for i, layer in enumerate(LAYERS) for p in layer if _names(module, p)),
        default=None,
    )
    return None if best is None else best[2]


def test_every_module_of_the_house_has_a_layer():
    assert [m for m in MODULES if m.split(".")[0] in ("pcabench", "solvers") and layer_of(m) is None] == []


def test_no_module_imports_from_a_layer_above_its_own():
    up = [
        f"{m} ({LAYERS[layer_of(m)][0]}) imports {t} ({LAYERS[layer_of(t)][0]})"
        for m, ts in GRAPH.items()
        if layer_of(m) is not None
        for t in ts
        if layer_of(t) is not None and layer_of(t) > layer_of(m)
    ]
    assert up == []


def test_an_upward_arrow_is_found():
    assert layer_of("pcabench.store.record") < layer_of("pcabench.studies.walls.section")
    assert layer_of("solvers.scene") < layer_of("solvers.search.celllist") < layer_of("pcabench.spec")


def test_a_study_is_one_folder_in_two_layers():
    """A study's plan sits with the presets, below the report; its sections and what they draw with the report;
    the machinery of presets is not a study's."""
    plan, report = layer_of("pcabench.studies.walls.plan"), layer_of("pcabench.reports.build")
    assert plan == layer_of("pcabench.studies.preset") == layer_of("pcabench.studies") < report
    assert layer_of("pcabench.studies.walls.section") == layer_of("pcabench.studies.paper.table4") == report
    assert layer_of("pcabench.studies.walls") == plan  # a study's face: its docstring, run before its plan
    assert layer_of("pcabench.studies.walls.gpu") == layer_of("pcabench.gpu.check") > report  # its GPU stage
    studies = {m.split(".")[2] for m in MODULES if m.startswith("pcabench.studies.") and m.count(".") >= 3}
    assert {"paper", "front", "walls", "cylinder", "high_order"} <= studies
    for study in studies:
        assert f"pcabench.studies.{study}.plan" in MODULES or f"pcabench.studies.{study}.section" in MODULES, study
        # its face is its docstring: importing its plan runs it, so a face that imported its sections would put
        # the report under the plan's layer, which the graph (module to module) would not show
        assert GRAPH[f"pcabench.studies.{study}"] == [], study


def test_every_study_folder_is_a_package():
    """The registries find a study's files through its package: a folder without ``__init__.py`` is skipped."""
    folders = {p.parent for p in (ROOT / "pcabench" / "studies").rglob("*.py")}
    assert [f for f in folders if not (f / "__init__.py").is_file()] == []


def test_the_report_imports_no_study():
    """pcabench/reports/ is the frame and the toolkits: it finds the studies' sections and pages through their
    registries and imports none of their modules (issue 68: everything of a study, the paper's cards page and
    summary included, in its folder)."""
    arrows = [f"{m} -> {t}" for m, ts in GRAPH.items() if m.startswith("pcabench.reports") for t in ts]
    assert [a for a in arrows if a.split(" -> ")[1].startswith("pcabench.studies")] == []
    assert "pcabench.studies.paper.page" in MODULES and "pcabench.studies.paper.cards" in MODULES
