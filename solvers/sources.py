"""The source files a registered class's code is made of: what keys its compiled loops (solvers/jitcache.py) and
a run's code key (pcabench/store/provenance.py), so that an edit of any of them compiles and runs again.

A built-in class (under ``solvers/``) is its MRO's files. A plug-in's code can come from anywhere it reaches: the
files of its MRO, then, for each of those outside ``solvers/``, every ``*.py`` of the distribution that installed
it (importlib.metadata), every ``*.py`` of its top-level package, and every module it imports (statically, by
its ``import`` statements, transitively) that is neither the interpreter's (the standard library) nor the
environment's (site-packages: numpy, numba ...), nor the suite's own (``solvers/``, ``pcabench/``). Nothing is
imported to find them: a module not loaded yet is found by its top-level name's spec and the folders below it.
"""

from __future__ import annotations

import ast
import functools
import importlib.util
import sys
import sysconfig
from importlib import metadata
from pathlib import Path

SOLVERS_ROOT = Path(__file__).resolve().parent


def class_sources(cls: type) -> list[Path]:
    """The source files of ``cls`` and of every class it inherits from (its whole MRO, built-in types left
    out): a subclass's compiled code can come from any of them (``class K(Gaussian)`` compiles Gaussian's
    ``compiled_gradient`` unless it overrides it). ValueError for a class with no file."""
    import inspect

    out = []
    for c in cls.__mro__:
        if c.__module__ in ("builtins", "abc", "typing"):
            continue
        try:
            out.append(Path(inspect.getsourcefile(c)))
        except (TypeError, OSError):  # a class made at run time (no file): its module's name cannot key it
            raise ValueError(f"jitcache: no source file for class {c.__qualname__} (of {cls.__qualname__})") from None
    return list(dict.fromkeys(out))


@functools.lru_cache(maxsize=None)
def code_sources(cls: type) -> tuple[Path, ...]:
    """Every source file ``cls``'s code can come from (the module's docstring): its MRO's, and for a plug-in its
    distribution's, its package's and its imports' outside the interpreter and the environment; resolved,
    sorted. Found once per class and process (what the files hold is read by their users: a key reads each
    file's bytes every time). ValueError for a class with no file."""
    out = set()
    for c, file in zip(_classes(cls), class_sources(cls)):
        file = file.resolve()
        out.add(file)
        if not file.is_relative_to(SOLVERS_ROOT):
            out |= _reach(file, c.__module__)
    return tuple(sorted(out))


def _classes(cls: type) -> list[type]:
    """``cls``'s MRO as :func:`class_sources` walks it, one class per file it lists."""
    import inspect

    seen, out = set(), []
    for c in cls.__mro__:
        if c.__module__ in ("builtins", "abc", "typing"):
            continue
        try:
            file = Path(inspect.getsourcefile(c))
        except (TypeError, OSError):  # a class made at run time (no file): as class_sources says it
            raise ValueError(f"jitcache: no source file for class {c.__qualname__} (of {cls.__qualname__})") from None
        if file not in seen:
            seen.add(file)
            out.append(c)
    return out


def _reach(file: Path, module: str) -> set[Path]:
    """The files a plug-in's module ``module`` at ``file`` reaches: its distribution's, its top-level package's,
    and its imports' (transitively) that are the user's own code."""
    out = set(_distribution_files(module.split(".")[0]))
    top = _module_file(module.split(".")[0])
    if top is not None and top.name == "__init__.py" and _own(top):
        out |= {p.resolve() for p in top.parent.rglob("*.py") if "__pycache__" not in p.parts}
    todo, seen = [(file, module)], set()
    while todo:
        path, name = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        out.add(path)
        for imported in _imports(path, name, path.name == "__init__.py"):
            found = _module_file(imported)
            if found is not None and _own(found) and found not in seen:
                todo.append((found, imported))
    return out


@functools.lru_cache(maxsize=None)
def _packages_distributions() -> dict:
    return metadata.packages_distributions()


def _distribution_files(top: str) -> set[Path]:
    """Every ``*.py`` the distribution(s) providing the top-level import ``top`` installed (none for an editable
    install's or an uninstalled module: their package and imports cover them)."""
    out = set()
    for dist_name in _packages_distributions().get(top, ()):
        try:
            dist = metadata.distribution(dist_name)
        except metadata.PackageNotFoundError:
            continue
        for part in dist.files or ():
            if str(part).endswith(".py"):
                path = Path(dist.locate_file(part))
                if path.is_file():
                    out.add(path.resolve())
    return out


@functools.lru_cache(maxsize=None)
def _not_own_roots() -> tuple[Path, ...]:
    """The interpreter's and the environment's folders (the standard library, site-packages), ``solvers/`` and the
    harness's (``pcabench/``: every file of it is in a run's code key already)."""
    paths = sysconfig.get_paths()
    roots = {paths[k] for k in ("stdlib", "platstdlib", "purelib", "platlib") if k in paths}
    roots |= {p for p in sys.path if p.rstrip("/").endswith(("site-packages", "dist-packages"))}
    harness = importlib.util.find_spec("pcabench")  # its top-level spec: nothing is imported
    if harness is not None and harness.origin:
        roots.add(str(Path(harness.origin).parent))
    return tuple(Path(p).resolve() for p in roots) + (SOLVERS_ROOT,)


def _own(path: Path) -> bool:
    """Whether ``path`` is a plug-in's own Python source: not the interpreter's, the environment's or solvers'."""
    return path.suffix == ".py" and not any(path.is_relative_to(root) for root in _not_own_roots())


def _module_file(name: str) -> Path | None:
    """The source file of the module ``name`` (resolved), without importing it: a loaded module's ``__file__``,
    else its top-level name's spec and the folders below it; None where there is none."""
    module = sys.modules.get(name)
    if module is not None:
        file = getattr(module, "__file__", None)
        return Path(file).resolve() if file else None
    top, *rest = name.split(".")
    try:
        spec = importlib.util.find_spec(top) if top not in sys.modules else sys.modules[top].__spec__
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return None
    path = Path(spec.origin)
    if not rest:
        return path.resolve()
    if path.name != "__init__.py":
        return None
    base = path.parent.joinpath(*rest)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate.resolve()
    return None


def _imports(path: Path, module: str, is_package: bool) -> list[str]:
    """The modules ``path`` (the module ``module``) imports, by name (``from m import n``: m, and m.n where n is
    a module); relative imports resolved. None for a file that does not parse."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8", errors="replace"))
    except (OSError, SyntaxError, ValueError):
        return []
    package = module if is_package else module.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".") if package else []
                if node.level - 1 > len(parts):
                    continue
                parent = ".".join(parts[: len(parts) - (node.level - 1)])
                base = f"{parent}.{base}".strip(".") if base else parent
            if base:
                out.append(base)
                out += [f"{base}.{a.name}" for a in node.names if a.name != "*"]
    return out
