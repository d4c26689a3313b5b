"""The one registry mechanism of pcabench: solvers, kernels, scenes, report sections and presets are each a
:class:`Registry`, found the same way.

An entry is found in three places, in this order:

* the modules of its package (a built-in is one new file there; ``base`` and
  ``registry`` modules and those starting with ``_`` are not searched), or, for
  a registry with a ``role``, the module of that name in each folder of its
  package (a study's ``plan.py``, its ``section.py``: a new one is one folder): the
  subclasses of the registry's ``base`` with a ``name`` of their own defined
  in the module (made into an entry by ``make``), or the instances of ``base``
  the module holds;
* the entry-point group of installed packages (``my-x = my_pkg.mod:MyX``);
* :meth:`Registry.register` in this process (tests, notebooks, the
  CONTRIBUTING recipes: :meth:`Registry.registered` for the length of a block).

Every name follows one rule (:data:`NAME`), and a name is taken once. A plug-in
that does not load, is not of the registry's ``base``, has no plain name of
its own or repeats a taken name is left out with one :class:`PluginWarning`;
:meth:`Registry.register` raises ValueError instead.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import pkgutil
import re
import warnings
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path
from typing import Any, Callable

# The one name rule of every registry (solvers, kernels, scenes): a name is stored in records, becomes part of
# file names and command lines, and is printed in Markdown tables, so it holds nothing a shell, a path or a
# table would read as syntax.
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,31}", re.ASCII)
NAME_RULE = "letters, digits, '.', '_', '-', starting with a letter or digit, at most 32"


class PluginWarning(UserWarning):
    """A plug-in left out of its registry, or registered under another name than its entry point's."""


def name_problem(name, what: str) -> str | None:
    """Why ``name`` cannot name a ``what`` (a solver, a kernel, a scene) under :data:`NAME` (None: it can)."""
    if not isinstance(name, str) or not NAME.fullmatch(name):
        return f"the {what} name {name!r:.80} is not a plain name ({NAME_RULE}): it names stored records"
    return None


def _own_name(obj):
    """The name ``obj`` sets itself: a class's from its own body (a subclass of a built-in inherits one that
    is not its own), an instance's attribute."""
    return obj.__dict__.get("name") if inspect.isclass(obj) else getattr(obj, "name", None)


class Registry:
    """The ``what`` (a word: "solver", "kernel") entries of one kind, each under its name.

    ``package`` holds the built-ins (one module each, searched in name order); ``group`` is the entry-point
    group of plug-ins; ``base`` what an entry is (a class whose subclasses are made into entries by ``make``,
    or whose instances are entries themselves); ``problem(obj)`` says why an object of ``base`` cannot be an
    entry (None: it can); ``order(entry)`` sorts the built-ins (default: the default name first, then by
    name); ``option`` names the choice in errors ("--scene"); ``declares(path)`` may keep a module from
    being imported (the solvers': only a module whose source defines a ``name``, so that no GPU library is
    touched to list them); ``role``: the built-ins are the module ``role`` of each sub-package of ``package``
    (``pcabench.studies.<study>.plan``), sub-packages on every folder of the package's ``__path__``, in name
    order; ``pinned``: a name keeps the object it was first registered as for the life of the
    process (the kernels': compiled loops and predictions are cached by kernel name).
    """

    def __init__(
        self,
        what: str,
        package: str,
        base: type,
        *,
        group: str | None = None,
        default: str | None = None,
        make: Callable[[type], Any] = lambda cls: cls,
        problem: Callable[[Any], str | None] = lambda obj: None,
        order: Callable[[Any], Any] | None = None,
        option: str | None = None,
        error: type[Exception] = ValueError,
        declares: Callable[[Path], bool] | None = None,
        pinned: bool = False,
        role: str | None = None,
    ):
        self.what, self.package, self.base, self.group, self.default = what, package, base, group, default
        self.make, self.problem, self.option, self.error, self.declares = make, problem, option, error, declares
        self.role = role  # the module of each sub-package that holds the built-ins (None: the package's modules)
        self.pinned = pinned  # a name keeps what it was first registered as for the life of the process
        self.order = order or (lambda entry: (entry.name != default, entry.name))
        self._found: dict[str, Any] | None = None
        self._builtins: dict[str, Any] | None = None
        self._added: dict[str, Any] = {}
        self._classes: dict[str, Any] = {}  # what each name was registered as in this process (names key caches)

    # ---------------------------------------------------------------- finding
    def why_not(self, obj, taken) -> str | None:
        """Why ``obj`` cannot be an entry beside the names ``taken`` (None: it can)."""
        is_class = inspect.isclass(obj)
        if not (
            (is_class and issubclass(obj, self.base) and not inspect.isabstract(obj)) or isinstance(obj, self.base)
        ):
            return f"not a concrete {self.base.__name__}" + (" subclass" if inspect.isclass(self.base) else "")
        name = _own_name(obj)
        if not name:
            inherited = getattr(obj, "name", None) if is_class else None
            return "it sets no name of its own" + (f" (it would inherit {inherited!r})" if inherited else "")
        return name_problem(name, self.what) or (
            f"the {self.what} name {name!r} is taken" if name in taken else self.problem(obj)
        )

    def _entry(self, obj):
        return self.make(obj) if inspect.isclass(obj) else obj

    def _modules(self) -> list[str]:
        """The dotted names of the modules that hold the built-ins, in name order."""
        package = importlib.import_module(self.package)
        if self.role is not None:  # a folder without __init__.py is no package: tests/test_imports.py finds none
            subs = sorted({i.name for i in pkgutil.iter_modules(package.__path__) if i.ispkg and i.name[0] != "_"})
            return [
                f"{self.package}.{sub}.{self.role}"
                for sub in subs
                if importlib.util.find_spec(f"{self.package}.{sub}.{self.role}") is not None
            ]
        folder = Path(package.__file__).parent
        return [
            f"{self.package}.{info.name}"
            for info in sorted(pkgutil.iter_modules([str(folder)]), key=lambda m: m.name)
            if info.name not in ("base", "registry")
            and not info.name.startswith("_")
            and (self.declares is None or self.declares(folder / f"{info.name}.py"))
        ]

    def _builtin(self) -> list:
        found, seen = [], set()
        for name in self._modules():
            mod = importlib.import_module(name)
            for _, obj in inspect.getmembers(mod):
                own = (
                    inspect.isclass(obj)
                    and issubclass(obj, self.base)
                    and obj is not self.base
                    and obj.__module__ == mod.__name__
                    and _own_name(obj)
                    and not inspect.isabstract(obj)
                ) or (not inspect.isclass(obj) and isinstance(obj, self.base))
                if own and id(obj) not in seen:
                    seen.add(id(obj))
                    found.append(self._entry(obj))
        return sorted(found, key=self.order)

    def _plugins(self, taken: set) -> list:
        found = []
        for entry in metadata.entry_points(group=self.group) if self.group else ():
            where = f"entry point {entry.name!r} of group {self.group} ({entry.value})"
            try:
                obj = entry.load()
            except BaseException as exc:  # noqa: BLE001 - a broken plug-in (even one calling sys.exit) is left out
                if isinstance(exc, KeyboardInterrupt):
                    raise
                warnings.warn(f"{where} left out: it does not load ({type(exc).__name__}: {exc})", PluginWarning, 3)
                continue
            why = self.why_not(obj, taken)
            if why:
                warnings.warn(f"{where} left out: {why}", PluginWarning, stacklevel=3)
                continue
            name = _own_name(obj)
            if entry.name != name:
                warnings.warn(f"{where}: registered as {name!r}, its own name", PluginWarning, stacklevel=3)
            found.append(self._entry(obj))
            taken.add(name)
        return found

    def all(self) -> dict[str, Any]:
        """{name: entry}: the built-ins (in their order), then plug-ins', then those registered here."""
        if self._found is None:
            builtin = self.builtins()
            self._found = {**builtin, **{e.name: e for e in self._plugins(set(builtin))}}
        return {**self._found, **self._added}

    def builtins(self) -> dict[str, Any]:
        """{name: entry} of the built-ins alone, in their order: no plug-in is loaded (a built-in's name is never a
        plug-in's, so what it answers of a built-in holds with them)."""
        if self._builtins is None:
            found = self._builtin()
            builtin = {e.name: e for e in found}
            if len(builtin) < len(found):  # two built-ins of one name: a mistake in the house, never a choice
                twice = sorted({e.name for e in found if sum(f.name == e.name for f in found) > 1})
                raise ValueError(f"two built-in {self.what}s share the name {', '.join(map(repr, twice))}")
            self._builtins = builtin
        return self._builtins

    def names(self) -> tuple[str, ...]:
        return tuple(self.all())

    def get(self, name: str):
        """The entry ``name``; ``error`` naming the option and the choices otherwise."""
        entries = self.all()
        try:
            return entries[name]
        except (KeyError, TypeError):
            raise self.error(f"{self.option or self.what} must be one of {', '.join(entries)} (got {name!r})") from None

    def __contains__(self, name) -> bool:
        return name in self.all()

    def cache_clear(self) -> None:
        """Search the packages and entry points again at the next look-up (tests that install a plug-in)."""
        self._found = self._builtins = None

    # ---------------------------------------------------------------- registering in this process
    def register(self, obj):
        """Add ``obj`` (a class of ``base`` or an instance) for this process; its entry. ValueError if it cannot
        be one: a bad name, a taken one, or (``pinned``) a name that was another object's in this process."""
        why = self.why_not(obj, set(self.all()))
        name = _own_name(obj)
        if why is None and self.pinned and self._classes.get(name, obj) is not obj:
            why = f"the {self.what} name {name!r} was another one's in this process (what it names is cached by name)"
        if why:
            raise ValueError(f"{self.what} {getattr(obj, '__name__', name)!r:.80}: {why}")
        self._classes[name] = obj
        self._added[name] = entry = self._entry(obj)
        return entry

    def unregister(self, name: str) -> None:
        """Remove an entry :meth:`register` added; ValueError for any other name."""
        if name not in self._added:
            raise ValueError(f"{self.what} {name!r} was not added by register(): only those can be removed")
        del self._added[name]

    @contextmanager
    def registered(self, obj):
        """``obj`` an entry while the block runs (its entry is the ``as`` value)."""
        entry = self.register(obj)
        try:
            yield entry
        finally:
            self.unregister(entry.name)


def declares_a_name(path: Path) -> bool:
    """Whether the module at ``path`` defines a class with a ``name`` attribute (read, not imported)."""
    import ast

    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, SyntaxError, UnicodeDecodeError):
        return False
    return any(
        isinstance(node, ast.ClassDef)
        and any(
            isinstance(stmt, (ast.Assign, ast.AnnAssign))
            and any(
                getattr(t, "id", None) == "name"
                for t in (stmt.targets if isinstance(stmt, ast.Assign) else [stmt.target])
            )
            for stmt in node.body
        )
        for node in tree.body
    )
