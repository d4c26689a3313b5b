"""Compile once per machine: the compiled loops specialised from templates and cached on disk by the hash
of their source (as PySPH's compyle does).

numba caches a function on disk (``cache=True``) only if it is a module-level function of a real file: it
cannot cache the closures a factory makes per kernel and precision, and it does not notice an edit to a
function it inlines from another file. So each specialisation is written out as a module of its own: the
text of a template (``solvers/loops/*.py``: the loops as plain module-level Python over a few free names,
such as the pair functions ``P``), then a footer that binds those names (``P = cpu_pairs('float64',
'gaussian')``) and compiles the loops with ``cache=True``. numba keeps the machine code beside that file
(``__pycache__``). The file is named by the SHA-256 of everything that decides the machine code:

* the generated text (the template's source, the bindings, the compile options);
* the source of every first-party module the template imports and of every module the bindings compile
  (``depends``: the pair physics, the kernel's class with every class it inherits from, so a plug-in kernel
  that subclasses a built-in is compiled again when the built-in's file changes);
* numba's, llvmlite's and Python's versions and the CPU target (the folder: :func:`target`).

An edit to any of them makes another name, hence another compile; undoing the edit finds the earlier file
and its machine code again, bit for bit. Files are created once (written aside, then linked into place), so
two processes filling the cache at once agree, and a process killed mid-write leaves no partial file.

Where: ``$PCABENCH_CACHE``, else ``$XDG_CACHE_HOME/pcabench``, else ``~/.cache/pcabench`` (:func:`cache_root`);
``pcabench cache`` shows and clears it (``$NUMBA_CACHE_DIR`` does not move these loops: it is numba's for other
functions). Faults end in a correct run with one :class:`JitCacheWarning`: an
unwritable or full cache folder (the loops are compiled in memory), a corrupt cache file (dropped and
rebuilt), a cache cleared under a running process (that process keeps its loops; later ones rebuild).
Nothing another user could have written is loaded (numba's index files are pickles, which run code): a
cache folder, from the root down, that is a link, is not the user's or is writable by others, or a cache
file that is not the user's, is not used (one warning naming it; the loops compiled in memory), as ssh
treats its folder; the folders jitcache makes are the user's alone (mode 700).
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import inspect
import os
import shutil
import stat
import sys
import threading
import warnings
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType

from solvers.sources import code_sources

ENV = "PCABENCH_CACHE"  # the cache root, if set
FIRST_PARTY = ("solvers",)  # a template's imports of these packages are part of its key
_lock = threading.Lock()
_modules: dict[str, ModuleType] = {}  # key -> the specialised module, once per process
_counts = {"loaded": 0, "compiled": 0}  # functions loaded from the disk cache / compiled, in this process
_uncached: list = []  # dispatchers compiled in memory (no cache): each overload is a compile
_warned: set = set()


class JitCacheWarning(UserWarning):
    """The on-disk cache could not be used for some loops: they were compiled in memory (the run is correct)."""


class NotCached(RuntimeError):
    """A compile refused within :func:`loads_only` (the function is not in the disk cache)."""


@contextmanager
def loads_only():
    """Within: numba may load compiled functions from the disk cache but compiles none (a miss raises
    :class:`NotCached`; numba's ``numba:compile`` event starts every compile, cached or in memory)."""
    from numba.core import event

    class Refuse(event.Listener):
        def on_start(self, ev):
            raise NotCached(f"{getattr(ev.data.get('dispatcher'), '__name__', 'a function')} is not cached")

        def on_end(self, ev):
            pass

    with event.install_listener("numba:compile", Refuse()):
        yield


def cache_root() -> Path:
    """The cache's root folder: ``$PCABENCH_CACHE``, else ``$XDG_CACHE_HOME/pcabench``, else ``~/.cache/pcabench``."""
    if os.environ.get(ENV):
        return Path(os.environ[ENV]).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "pcabench"


def target() -> str:
    """The compile target's name: numba's and Python's versions, the CPU and a digest of its features
    (numba's ``NUMBA_CPU_NAME`` / ``NUMBA_CPU_FEATURES`` where set, else the host's)."""
    import llvmlite
    import numba
    from llvmlite import binding

    cpu = numba.config.CPU_NAME or binding.get_host_cpu_name()
    features = numba.config.CPU_FEATURES or binding.get_host_cpu_features().flatten()
    digest = hashlib.sha256(f"{cpu}|{features}|{llvmlite.__version__}".encode()).hexdigest()[:10]
    return f"numba{numba.__version__}-py{sys.version_info[0]}{sys.version_info[1]}-{cpu}-{digest}"


def jit_folder() -> Path:
    """Where this machine's specialised modules and their machine code are: ``<root>/jit/<target>``."""
    return cache_root() / "jit" / target()


class UntrustedCache(OSError):
    """A cache folder or file another user could have written: its contents are never loaded (numba's index is
    a pickle, and a pickle runs code)."""


def untrusted(path: Path, folder: bool) -> str:
    """Why ``path`` may not be trusted ('' if it may): a link; not owned by this user; a folder writable by its
    group or by all (anyone there could plant a file). As ssh treats its folder."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return ""
    uid = os.getuid()
    if stat.S_ISLNK(st.st_mode):
        return "is a link"
    if st.st_uid != uid:
        return f"is owned by user id {st.st_uid}, not by you ({uid})"
    if folder and st.st_mode & 0o022:
        return f"is writable by others (mode {stat.S_IMODE(st.st_mode):o}; chmod go-w it)"
    return ""


def trusted_folder(folder: Path) -> Path:
    """``folder`` (the JIT folder of this target) and its ``__pycache__``, made where missing (mode 700) and
    checked with every folder from the cache root down: UntrustedCache naming the first that fails."""
    root = cache_root()
    parts = folder.relative_to(root).parts
    chain = [root, *(root.joinpath(*parts[: i + 1]) for i in range(len(parts))), folder / "__pycache__"]
    for path in chain:
        if not os.path.lexists(path):
            path.mkdir(mode=0o700, parents=True, exist_ok=True)
        why = untrusted(path, folder=True)
        if why:
            raise UntrustedCache(f"{path} {why}")
    return folder


def _warn(kind: str, what: str, exc: BaseException | None = None) -> None:
    """One JitCacheWarning per kind of fault (``folder``, ``read``, ``write``) and process."""
    if kind in _warned:
        return
    _warned.add(kind)
    detail = f" ({type(exc).__name__}: {exc})" if exc is not None else ""
    warnings.warn(f"{what}{detail}; compiled in memory, the results are unchanged", JitCacheWarning, stacklevel=3)


def _source_file(dep) -> Path:
    """The source file of ``dep``: a module, a module's name, a class or function, or a path."""
    if isinstance(dep, (str, Path)) and str(dep).endswith(".py"):
        return Path(dep)
    if isinstance(dep, str):
        spec = importlib.util.find_spec(dep)
        if spec is None or not spec.origin:
            raise ValueError(f"jitcache: no source for module {dep!r}")
        return Path(spec.origin)
    return Path(inspect.getsourcefile(dep))


def _sources(dep) -> list[Path]:
    """The source files ``dep`` stands for: every file a class's code can come from (its MRO's, and a plug-in's
    package, distribution and own imports: :func:`solvers.sources.code_sources`), else its one file."""
    return code_sources(dep) if inspect.isclass(dep) else [_source_file(dep)]


def imports_of(text: str) -> list[str]:
    """The first-party modules a template imports (absolute imports only: a template is written out
    beside no package)."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.ImportFrom) and node.level:
            raise ValueError("jitcache: a template imports absolutely (it is compiled outside its package)")
        names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module]
        out += [n for n in names if n.split(".")[0] in FIRST_PARTY]
    return sorted(set(out))


def render(template: str, bind: dict, functions: dict, imports: tuple = (), cache: bool = True) -> str:
    """The text of one specialisation: the template module's source, then the footer that binds ``bind``
    (name -> Python expression) after ``imports`` (import lines) and compiles each of ``functions``
    (name -> (decorator, options), e.g. ``("numba.njit", {"nogil": True})``) with ``cache``."""
    source = _source_file(template).read_text()
    options = {repr(o) for _, o in functions.values()}
    lines = [
        f"# Generated by solvers.jitcache from {template}: its file name is the hash of what produced it.",
        f"# specialisation: {', '.join(f'{k} = {v}' for k, v in bind.items()) or 'none'}; {'; '.join(sorted(options))}",
        source.rstrip("\n"),
        "",
        "",
        "# ---- the specialisation (solvers.jitcache.render)",
        *imports,
        *(f"{name} = {expr}" for name, expr in bind.items()),
    ]
    for name, (decorator, options) in functions.items():
        opts = ", ".join(f"{k}={v!r}" for k, v in {**options, "cache": cache}.items())
        lines.append(f"{name} = {decorator}({opts})({name})")
    return "\n".join(lines) + "\n"


def key(text: str, depends: tuple = ()) -> str:
    """SHA-256 of the generated ``text``, the source of the modules it imports and of ``depends``, and the target."""
    h = hashlib.sha256(text.encode())
    for dep in sorted({str(p) for d in (*imports_of(text), *depends) for p in _sources(d)}):
        h.update(dep.encode() + b"\0" + _digest(dep) + b"\0")
    h.update(target().encode())
    return h.hexdigest()


_digests: dict = {}  # path -> (stat stamp, SHA-256): a source file read once while it is unchanged


def _digest(path: str) -> bytes:
    """The SHA-256 of a source file's bytes (read again when its inode, size, mtime or ctime changes)."""
    st = os.stat(path)
    stamp = (st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)
    known = _digests.get(path)
    if known is None or known[0] != stamp:
        known = _digests[path] = (stamp, hashlib.sha256(Path(path).read_bytes()).digest())
    return known[1]


def specialise(
    template: str, bind: dict, functions: dict, imports: tuple = (), depends: tuple = (), cache: bool = True
):
    """The module of ``template`` specialised by ``bind`` with ``functions`` compiled (see
    :func:`render`), loaded from the disk cache where its key is there, written there where not, or, with
    ``cache`` False or where the cache folder cannot be used, compiled in memory. Once per process.
    ``depends``: what the bindings compile besides the template's own imports (modules, names, files)."""
    text = render(template, bind, functions, imports, cache=True)
    try:
        name = key(text, depends)
    except (OSError, TypeError, ValueError) as exc:  # a source that cannot be read cannot key a cache
        name, cache = hashlib.sha256(f"{text}{depends!r}".encode()).hexdigest(), False
        _warn("source", f"the source of what {template} compiles cannot be read, so it is not cached", exc)
    with _lock:
        if name in _modules:
            return _modules[name]
        module = None
        if cache:
            try:
                module = _load(_written(text, name, template), name, functions)
            except Exception as exc:  # noqa: BLE001 - unwritable, full, removed: compile in memory
                _warn("folder", f"the JIT cache folder {jit_folder()} cannot be used", exc)
        if module is None:
            module = _in_memory(render(template, bind, functions, imports, cache=False), name, functions)
        _modules[name] = module
        return module


def _written(text: str, name: str, template: str) -> Path:
    """The generated file for ``name``, created once: written aside, then linked into place (never replaced,
    so a file another process is reading never changes; numba's index is stamped by the file's mtime)."""
    folder = trusted_folder(jit_folder())
    path = folder / f"{template.rsplit('.', 1)[-1]}_{name[:24]}.py"
    if path.is_symlink():
        raise OSError(f"{path} is a link")
    for file in (path, *sorted((folder / "__pycache__").glob(f"{path.stem}.*"))):  # numba's index and code
        why = untrusted(file, folder=False)
        if why:
            raise UntrustedCache(f"{file} {why}")
    if path.exists() and path.read_text() == text:
        return path
    tmp = folder / f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp"
    try:
        with open(tmp, "x") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        if path.exists():  # a torn or foreign file under our name (it cannot be ours: ours are whole): replace
            os.replace(tmp, path)
        else:
            try:
                os.link(tmp, path)
            except FileExistsError:  # another process created it first, from the same text
                pass
    finally:
        tmp.unlink(missing_ok=True)
    if path.read_text() != text:
        raise OSError(f"{path} does not hold the text it is named for")
    return path


def _module_name(name: str) -> str:
    return f"_pcabench_jit_{name[:24]}"


def _load(path: Path, name: str, functions: dict) -> ModuleType:
    """Import the generated file as a module of its own (registered in sys.modules: numba rebuilds a cached
    function's environment from its module's name), its compiled functions guarded against cache faults."""
    from numba.core import config as numba_config

    modname = _module_name(name)
    spec = importlib.util.spec_from_file_location(modname, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    # numba picks a function's cache folder when it is decorated: $NUMBA_CACHE_DIR would take these loops out of
    # this folder and so out of this module's checks (a corrupt file rebuilt, a folder others can write refused)
    held, numba_config.CACHE_DIR = numba_config.CACHE_DIR, ""
    try:
        spec.loader.exec_module(module)
    except Exception:
        sys.modules.pop(modname, None)
        raise
    finally:
        numba_config.CACHE_DIR = held
    for fn in functions:
        _guard(getattr(module, fn))
    return module


def _in_memory(text: str, name: str, functions: dict) -> ModuleType:
    """The specialisation compiled without a disk cache (the text run as a module with no file)."""
    modname = _module_name(name) + "_mem"
    module = ModuleType(modname)
    module.__file__ = f"<{modname}>"
    sys.modules[modname] = module
    exec(compile(text, module.__file__, "exec"), module.__dict__)
    _uncached.extend(getattr(module, fn) for fn in functions)
    return module


def _guard(dispatcher) -> None:
    """Count the dispatcher's cache loads and compiles; a cache file that cannot be read is dropped (the
    function compiled and the entry written again), one that cannot be written is skipped, each with one
    warning. (numba's ``Dispatcher._cache``: ``load_overload`` and ``save_overload`` are its two doors.)"""
    cache = getattr(dispatcher, "_cache", None)
    if cache is None or not hasattr(cache, "load_overload"):
        _uncached.append(dispatcher)
        return
    load, save = cache.load_overload, cache.save_overload

    def load_overload(sig, target_context):
        try:
            data = load(sig, target_context)
        except Exception as exc:  # noqa: BLE001 - corrupt or truncated: rebuild
            _warn("read", f"a JIT cache file ({dispatcher.__name__}) could not be read: rebuilt", exc)
            try:
                cache.flush()  # an empty index in place of the unreadable one
            except Exception:  # noqa: BLE001
                pass
            return None
        if data is not None:
            _counts["loaded"] += 1
        return data

    def save_overload(sig, data):
        _counts["compiled"] += 1
        try:
            save(sig, data)
        except Exception as exc:  # noqa: BLE001 - full, removed, unwritable: the compiled code is in memory
            _warn("write", f"a JIT cache file ({dispatcher.__name__}) could not be written", exc)

    cache.load_overload, cache.save_overload = load_overload, save_overload


def counts() -> dict:
    """Functions loaded from the disk cache and compiled in this process so far (a compile in memory counts)."""
    in_memory = sum(len(getattr(d, "overloads", {}) or {}) for d in _uncached)
    return {"loaded": _counts["loaded"], "compiled": _counts["compiled"] + in_memory}


def entries(root: Path | None = None) -> list[dict]:
    """Every specialised module under the cache root: its target, file, size with its machine code (B) and
    how many compiled functions are stored for it."""
    root = (root or cache_root()) / "jit"
    out = []
    for path in sorted(root.glob("*/*.py")):
        stem = path.stem
        code = list((path.parent / "__pycache__").glob(f"{stem}.*")) if (path.parent / "__pycache__").is_dir() else []
        size = path.stat().st_size + sum(p.stat().st_size for p in code)
        with open(path) as f:
            f.readline()
            what = f.readline().removeprefix("# specialisation: ").strip()
        out.append(
            {
                "target": path.parent.name,
                "module": stem,
                "specialisation": what,
                "bytes": size,
                "functions": sum(1 for p in code if p.suffix == ".nbi"),
            }
        )
    return out


def clear(root: Path | None = None) -> int:
    """Remove the compiled cache (the ``jit`` folder under the root); bytes freed. The folder is renamed away
    first, so a process using it sees it gone at once and rebuilds (its loops in memory are untouched)."""
    folder = (root or cache_root()) / "jit"
    if folder.is_symlink():
        raise OSError(f"{folder} is a link: not clearing through it")
    if not folder.exists():
        return 0
    size = sum(p.stat().st_size for p in folder.rglob("*") if p.is_file() and not p.is_symlink())
    doomed = folder.with_name(f".jit-clearing-{os.getpid()}")
    os.replace(folder, doomed)
    shutil.rmtree(doomed, ignore_errors=True)
    return size
