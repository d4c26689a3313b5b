"""The on-disk JIT cache (solvers/jitcache.py): a second process loads instead of compiling and gets the same
numbers bit for bit; an edit to the code a loop is made of recompiles it and undoing the edit brings the
earlier machine code back; races, torn and corrupt files and an unusable folder end in a correct run."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from solvers import jitcache

ROOT = Path(__file__).resolve().parents[1]

# One tiny lagrangian run in a fresh process: the fields' bytes as a digest, and what the cache did.
# A kernel plug-in file may be given (argv[2]): registered, then used (its source is part of the key).
PROBE = textwrap.dedent(
    """
    import hashlib, json, sys, warnings
    warnings.simplefilter("always")
    caught = []
    warnings.showwarning = lambda message, category, *a, **k: caught.append(f"{category.__name__}: {message}")
    from solvers import Scene, jitcache, make_solver
    from solvers.interface import tiny_scene
    kernel = "gaussian"
    if len(sys.argv) > 2:
        import importlib.util
        spec = importlib.util.spec_from_file_location("plugin_kernel", sys.argv[2])
        mod = sys.modules["plugin_kernel"] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        from solvers.kernels import register
        register(mod.Plugin)
        kernel = mod.Plugin.name
    solver = make_solver(sys.argv[1])
    solver.input(tiny_scene(Scene(dx=1.0, kernel=kernel)).replace(steps=4))
    solver.init()
    for _ in range(4):
        solver.rates(True, True)
        solver.kick(0.5)
        solver.advance(1.0)
    f = solver.output()
    digest = hashlib.sha256(b"".join(a.tobytes() for a in (f.x, f.y, f.u, f.v, f.drho))).hexdigest()
    print(json.dumps({"digest": digest, **jitcache.counts(), "warnings": caught}))
    """
)


def probe(cache: Path, solver: str = "allpair-cpu", kernel_file: Path | None = None, **env) -> dict:
    """PROBE in a fresh process with the cache at ``cache``."""
    args = [sys.executable, "-c", PROBE, solver] + ([str(kernel_file)] if kernel_file else [])
    environ = {**os.environ, "PCABENCH_CACHE": str(cache), **env}
    out = subprocess.run(args, capture_output=True, text=True, cwd=ROOT, env=environ, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def code_files(cache: Path) -> list[Path]:
    return sorted(cache.glob("jit/*/__pycache__/*.nb[ic]"))


PLUGIN = textwrap.dedent(
    """
    import math
    import numpy as np
    from solvers.kernels.constants import GRAD0, INV_H2
    from solvers.kernels import Kernel

    class Plugin(Kernel):
        name = "plugin-gauss"
        support = None
        norm = 1.0 / math.pi

        def value(self, r, h):
            return np.exp(-((np.asarray(r) / h) ** 2)) / (math.pi * h * h)

        def gradient(self, r, h):
            return -2.0 * np.exp(-((np.asarray(r) / h) ** 2)) / (math.pi * h**4)

        def compiled_gradient(self, dtype, exp_neg):
            scale = np.dtype(dtype).type(SCALE)

            def gradient(r2, k):
                return scale * k[GRAD0] * exp_neg(r2 * k[INV_H2])

            return gradient
    """
)


def test_a_second_process_loads_every_loop_and_gets_the_same_numbers(tmp_path):
    cold = probe(tmp_path)
    assert cold["compiled"] > 0 and cold["loaded"] == 0 and not cold["warnings"]
    warm = probe(tmp_path)
    assert warm["compiled"] == 0, "the second process compiled again"
    assert warm["loaded"] == cold["compiled"]
    assert warm["digest"] == cold["digest"]  # bit for bit
    assert not warm["warnings"]


def test_numba_cache_dir_does_not_take_the_loops_out_of_the_cache(tmp_path):
    """With $NUMBA_CACHE_DIR set, numba would keep the loops in that folder, outside jitcache's checks: they are
    kept in jitcache's folder all the same, and loaded from there by the next process."""
    elsewhere = tmp_path / "numba"
    elsewhere.mkdir()
    cold = probe(tmp_path / "cache", NUMBA_CACHE_DIR=str(elsewhere))
    assert cold["compiled"] > 0 and code_files(tmp_path / "cache") and not any(elsewhere.rglob("*.nb[ic]"))
    warm = probe(tmp_path / "cache", NUMBA_CACHE_DIR=str(elsewhere))
    assert warm["compiled"] == 0 and warm["loaded"] == cold["compiled"] and warm["digest"] == cold["digest"]


def test_an_edit_to_a_plugin_kernel_recompiles_and_undoing_it_restores_the_machine_code(tmp_path):
    plugin = tmp_path / "plugin_kernel.py"
    cache = tmp_path / "cache"
    plugin.write_text(PLUGIN.replace("SCALE", "1.0"))
    first = probe(cache, kernel_file=plugin)
    assert first["compiled"] > 0
    plugin.write_text(PLUGIN.replace("SCALE", "1.25"))  # the kernel's G, edited
    edited = probe(cache, kernel_file=plugin)
    assert edited["compiled"] > 0, "an edited kernel was served from the cache"
    assert edited["digest"] != first["digest"]
    plugin.write_text(PLUGIN.replace("SCALE", "1.0"))  # the edit undone
    undone = probe(cache, kernel_file=plugin)
    assert undone["compiled"] == 0 and undone["loaded"] > 0
    assert undone["digest"] == first["digest"]


def test_a_kernel_that_subclasses_another_recompiles_when_the_class_it_inherits_from_is_edited(tmp_path):
    """The key holds the kernel class's whole MRO: ``class Plugin(Parent)`` compiles Parent's
    ``compiled_gradient``, so an edit to Parent's file (a built-in's, or another plug-in's) must not be served
    from the cache under the subclass's unchanged file."""
    parent = tmp_path / "parent_kernel.py"
    child = tmp_path / "child_kernel.py"
    parent.write_text(PLUGIN.replace("class Plugin(Kernel):", "class Parent(Kernel):").replace("SCALE", "1.0"))
    child.write_text(
        "import sys, os\n"
        "sys.path.insert(0, os.path.dirname(__file__))\n"
        "from parent_kernel import Parent\n\n\n"
        "class Plugin(Parent):\n"
        '    name = "plugin-sub"\n'
    )
    cache = tmp_path / "cache"
    first = probe(cache, kernel_file=child)
    assert first["compiled"] > 0
    parent.write_text(PLUGIN.replace("class Plugin(Kernel):", "class Parent(Kernel):").replace("SCALE", "1.25"))
    edited = probe(cache, kernel_file=child)
    assert edited["compiled"] > 0, "the subclass's loops were served from the cache after its parent's edit"
    assert edited["digest"] != first["digest"]


HELPED = textwrap.dedent(
    """
    import os, sys
    sys.path.insert(0, os.path.dirname(__file__))
    import numpy as np
    from plugin_helper import shape
    from solvers.kernels.constants import GRAD0, INV_H2
    from solvers.kernels.gaussian import Gaussian

    class Plugin(Gaussian):
        name = "plugin-helped"

        def compiled_gradient(self, dtype, exp_neg):
            def gradient(r2, k):
                return shape(k[GRAD0] * exp_neg(r2 * k[INV_H2]))

            return gradient
    """
)


def test_a_kernel_recompiles_when_a_helper_module_its_compiled_code_calls_is_edited(tmp_path):
    """The kernel's compiled gradient calls a jitted function of another module beside it (a plug-in's package,
    or a lone module's sibling): an edit there is an edit of the loops (the key holds what the plug-in's own
    modules import, solvers/sources.py)."""
    kernel, helper, cache = tmp_path / "plugin_kernel.py", tmp_path / "plugin_helper.py", tmp_path / "cache"
    kernel.write_text(HELPED)
    helper.write_text("import numba\n\n\n@numba.njit\ndef shape(g):\n    return g\n")
    first = probe(cache, kernel_file=kernel)
    assert first["compiled"] > 0
    helper.write_text("import numba\n\n\n@numba.njit\ndef shape(g):\n    return 1.25 * g\n")
    edited = probe(cache, kernel_file=kernel)
    assert edited["compiled"] > 0, "the loops were served from the cache after the helper's edit"
    assert edited["digest"] != first["digest"]


def test_the_key_covers_the_pair_physics_numba_and_the_target(monkeypatch):
    text = jitcache.render("solvers.loops.allpair", {"P": "cpu_pairs('float64', 'gaussian')"}, {})
    base = jitcache.key(text, ("solvers.physics.pairs",))
    assert base == jitcache.key(text, ("solvers.physics.pairs",))  # a key is a function of its inputs
    assert base != jitcache.key(text, ("solvers.physics.pairs", "solvers.kernels.constants"))  # another source
    other = jitcache.render("solvers.loops.allpair", {"P": "cpu_pairs('float32', 'gaussian')"}, {})
    assert base != jitcache.key(other, ("solvers.physics.pairs",))  # another precision
    assert "solvers.kernels.constants" in jitcache.imports_of(jitcache.render("solvers.loops.cells", {}, {}))
    monkeypatch.setattr(jitcache, "target", lambda: "numba0.0-py0-othercpu-0")
    assert base != jitcache.key(text, ("solvers.physics.pairs",))  # another numba or CPU


def test_two_processes_filling_the_cache_at_once_agree(tmp_path):
    environ = {**os.environ, "PCABENCH_CACHE": str(tmp_path)}
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", PROBE, "allpair-cpu"], cwd=ROOT, env=environ, stdout=subprocess.PIPE, text=True
        )
        for _ in range(2)
    ]
    outs = [json.loads(p.communicate(timeout=600)[0].strip().splitlines()[-1]) for p in procs]
    assert all(p.returncode == 0 for p in procs)
    assert outs[0]["digest"] == outs[1]["digest"]
    assert not outs[0]["warnings"] and not outs[1]["warnings"]
    after = probe(tmp_path)
    assert after["compiled"] == 0 and after["digest"] == outs[0]["digest"]


def test_a_process_killed_while_compiling_leaves_a_cache_that_works(tmp_path):
    reference = probe(tmp_path / "clean")
    environ = {**os.environ, "PCABENCH_CACHE": str(tmp_path / "cache")}
    proc = subprocess.Popen([sys.executable, "-c", PROBE, "allpair-cpu"], cwd=ROOT, env=environ)
    deadline = time.time() + 120
    while not list((tmp_path / "cache").glob("jit/*/*.py")) and time.time() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)  # compiling now
    proc.kill()
    proc.wait()
    after = probe(tmp_path / "cache")
    assert after["digest"] == reference["digest"]
    assert not after["warnings"]


@pytest.mark.parametrize("damage", ["truncated", "garbage"])
def test_a_corrupt_cache_file_is_rebuilt_with_one_warning(tmp_path, damage):
    cold = probe(tmp_path)
    for path in code_files(tmp_path):
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 3] if damage == "truncated" else os.urandom(len(data)))
    hurt = probe(tmp_path)
    assert hurt["digest"] == cold["digest"]
    assert len(hurt["warnings"]) == 1 and "JitCacheWarning" in hurt["warnings"][0], hurt["warnings"]
    healed = probe(tmp_path)
    assert healed["compiled"] == 0 and healed["digest"] == cold["digest"] and not healed["warnings"]


def test_a_torn_generated_module_is_replaced(tmp_path):
    cold = probe(tmp_path)
    for path in tmp_path.glob("jit/*/*.py"):
        path.write_text(path.read_text()[:200])  # a writer killed mid-file (not how jitcache writes: the worst case)
    again = probe(tmp_path)
    assert again["digest"] == cold["digest"]


def test_an_unusable_cache_folder_compiles_in_memory_with_one_warning(tmp_path):
    reference = probe(tmp_path / "ok")
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    out = probe(blocker / "cache")  # cannot be created (as root too)
    assert out["digest"] == reference["digest"]
    assert out["compiled"] > 0 and out["loaded"] == 0
    assert len(out["warnings"]) == 1 and "JitCacheWarning" in out["warnings"][0]


def test_a_cache_folder_others_can_write_is_not_loaded_from(tmp_path):
    """A shared cache folder (mode 777: another user could plant numba's pickled index there) is never loaded
    from: one warning naming it, the loops compiled in memory, the same numbers."""
    cache = tmp_path / "cache"
    first = probe(cache)
    assert first["compiled"] > 0
    (target,) = cache.glob("jit/*")
    for index in target.glob("__pycache__/*.nbi"):  # what a planted pickle would look like: it must not be read
        index.write_bytes(b"cos\nsystem\n(S'touch " + str(tmp_path / "pwned").encode() + b"'\ntR.")
    target.chmod(0o777)
    out = probe(cache)
    assert out["digest"] == first["digest"] and out["loaded"] == 0 and out["compiled"] > 0
    assert len(out["warnings"]) == 1 and f"{target} is writable by others" in out["warnings"][0]
    assert not (tmp_path / "pwned").exists()


def test_a_cache_file_of_another_user_is_not_loaded(tmp_path, monkeypatch):
    """Owned by another user id (this process made it, so it is shown as another's by the uid it compares
    with): refused, naming the folder or file, before any of it is read."""
    from solvers import jitcache

    monkeypatch.setenv("PCABENCH_CACHE", str(tmp_path))
    folder = jitcache.trusted_folder(jitcache.jit_folder())
    assert jitcache.untrusted(folder, folder=True) == ""
    planted = folder / "__pycache__" / "x.nbi"
    planted.write_bytes(b"")
    monkeypatch.setattr(jitcache.os, "getuid", lambda: os.stat(planted).st_uid + 1)
    assert "is owned by user id" in jitcache.untrusted(planted, folder=False)
    with pytest.raises(jitcache.UntrustedCache, match="is owned by user id"):
        jitcache.trusted_folder(jitcache.jit_folder())


TEMPLATE = """
def triple(x):
    return 3 * x
"""


def test_a_cache_cleared_under_a_running_process_does_not_break_it(tmp_path, monkeypatch):
    monkeypatch.setenv("PCABENCH_CACHE", str(tmp_path))
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / f"tmpl_{os.getpid()}.py").write_text(TEMPLATE + f"\nSALT = {time.time_ns()}\n")  # a key of its own
    mod = jitcache.specialise(f"tmpl_{os.getpid()}", {}, {"triple": ("numba.njit", {})}, ("import numba",))
    assert mod.triple(2) == 6  # compiled and stored
    assert jitcache.clear() > 0 and not (tmp_path / "jit").exists()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert mod.triple(2.5) == 7.5  # another signature: compiled, its cache folder gone
        assert mod.triple(np.float32(2)) == 6
    assert sum(issubclass(w.category, jitcache.JitCacheWarning) for w in caught) <= 1


def test_pcabench_cache_shows_and_clears(tmp_path, capsys):
    from tests.conftest import cli_main

    env = {"PCABENCH_CACHE": str(tmp_path)}
    probe(tmp_path)
    os.environ.update(env)
    try:
        code, out, _ = cli_main("cache", "--json", capsys=capsys)
        shown = json.loads(out)
        assert code == 0 and shown["root"] == str(tmp_path) and shown["entries"]
        assert all(e["functions"] > 0 for e in shown["entries"])
        assert any("cpu_pairs('float64', 'gaussian'" in e["specialisation"] for e in shown["entries"])
        code, out, _ = cli_main("cache", "--clear", capsys=capsys)
        assert code == 0 and not list(tmp_path.glob("jit/*/*.py"))
    finally:
        os.environ.pop("PCABENCH_CACHE")


def test_pcabench_cache_on_a_file_is_one_line_naming_it(tmp_path, monkeypatch, capsys):
    from tests.conftest import cli_main

    blocker = tmp_path / "not-a-folder"
    blocker.write_text("x")
    monkeypatch.setenv("PCABENCH_CACHE", str(blocker / "cache"))
    code, out, err = cli_main("cache", capsys=capsys)
    assert code == 2 and str(blocker) in err and len(err.strip().splitlines()) == 1
    assert "Traceback" not in err and blocker.read_text() == "x"


def test_loads_only_loads_what_is_cached_and_compiles_nothing(tmp_path, monkeypatch):
    monkeypatch.setenv("PCABENCH_CACHE", str(tmp_path))
    monkeypatch.syspath_prepend(str(tmp_path))
    name = f"tmpl_lo_{os.getpid()}"
    (tmp_path / f"{name}.py").write_text(TEMPLATE + f"\nSALT = {time.time_ns()}\n")
    mod = jitcache.specialise(name, {}, {"triple": ("numba.njit", {})}, ("import numba",))
    before = jitcache.counts()
    with jitcache.loads_only(), pytest.raises(jitcache.NotCached, match="triple"):
        mod.triple(2)  # not in the cache yet: refused, not compiled
    assert jitcache.counts() == before and not mod.triple.overloads
    assert mod.triple(2) == 6  # outside, it compiles (and stores)
    assert jitcache.counts()["compiled"] == before["compiled"] + 1


WARM = textwrap.dedent(
    """
    import json, sys
    from pcabench.execute.preload import warm
    from pcabench.spec import RunSpec
    from solvers import Scene, jitcache
    cached = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    other = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2, precision="float32", kernel="wendland-c2")).resolved()
    threaded = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2), threads=2).resolved()
    if sys.argv[1:] == ["fill"]:  # a run of ``cached`` before: its loops compiled into the cache
        from solvers import make_solver
        from solvers.interface import tiny_scene
        solver = make_solver("linkedlist-cpu")
        solver.input(tiny_scene(cached.scene))
        solver.warmup()
        sys.exit(0)
    n = warm([cached, other, threaded])
    import numba.np.ufunc.parallel as par
    print(json.dumps({"warmed": n, **jitcache.counts(), "threads_started": bool(par._is_initialized)}))
    """
)


def test_the_forkservers_warm_loads_the_cached_configurations_and_compiles_none(tmp_path):
    """pcabench/execute/preload.py: what a sweep's server loads before it forks the runs (a child loads nothing)."""
    environ = {**os.environ, "PCABENCH_CACHE": str(tmp_path)}
    subprocess.run([sys.executable, "-c", WARM, "fill"], check=True, cwd=ROOT, env=environ, capture_output=True)
    out = subprocess.run([sys.executable, "-c", WARM], capture_output=True, text=True, cwd=ROOT, env=environ)
    assert out.returncode == 0, out.stderr[-3000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["warmed"] == 1  # the cached one; float32 wendland is not cached, threads are never warmed
    assert got["loaded"] > 0 and got["compiled"] == 0
    assert not got["threads_started"]  # numba's pool does not survive a fork: the server never starts it
