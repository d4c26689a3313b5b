"""pcabench advise: the fastest stored run reaching an error, like with like, and the paper's method beside it."""

from __future__ import annotations

import json

import pytest

from pcabench import store
from pcabench.execute.sweep import failed_record
from pcabench.predict.advice import advise
from pcabench.reports.frame import load as load_frame
from pcabench.spec import RunSpec
from solvers import Scene

from .conftest import cli_main


def _row(path, seconds, mse, strip=True, model="linear", mse_isothermal=None, status="ok", **method):
    dx = method.pop("dx", 0.2)
    kw = dict(dx=dx, t_end=10.0, model=model, **method)
    if strip:
        kw["strip_height"] = 4.0
    spec = RunSpec("linkedlist-cpu", Scene(**kw)).resolved()
    rec = failed_record(spec, status, "", "m")
    rec.steps, rec.t_end, rec.mse, rec.me, rec.mean_neighbours = spec.scene.n_steps, 10.0, mse, 0.001, 50.0
    rec.mse_isothermal = mse_isothermal
    rec.stages = {"input": 0.0, "init": 0.0, "snp": 0.0, "pi": seconds, "su": 0.0, "output": 0.0}
    store.append(rec, path)


@pytest.fixture
def results(tmp_path):
    path = tmp_path / "results" / store.store_name("m", "h")
    path.parent.mkdir()
    _row(path, 50.0, 0.008)  # the paper's method on the strip
    _row(path, 2.0, 0.006, kernel="wendland-c2", h_factor=2.0, cfl=2.5)
    _row(path, 1.0, 0.02, kernel="wendland-c4", h_factor=1.3, cfl=1.0)  # faster, not accurate enough
    _row(path, 0.1, 0.001, strip=False, kernel="wendland-c4", cfl=1.0, status="unstable")  # failed: never advised
    # the fastest and most accurate, but at CFL 3 past its predicted stable 2.35: bounded only for being short
    _row(path, 0.5, 0.0012, kernel="wendland-c2", h_factor=1.3, cfl=3.0)
    _row(path, 900.0, 0.007, strip=False)  # the paper's method on the full domain
    _row(path, 30.0, 0.007, strip=False, kernel="wendland-c2", h_factor=2.0, cfl=2.5)
    _row(path, 80.0, 0.09, model="lagrangian", mse_isothermal=0.011)
    # within the moving models' margin: 0.7 of the stable 3.52 (the one margin rule, stability.MARGIN)
    _row(path, 3.0, 0.09, model="lagrangian", mse_isothermal=0.012, kernel="wendland-c2", h_factor=2.0, cfl=2.4)
    return path.parent


def test_the_fastest_run_reaching_the_error_against_the_paper_method_on_the_same_domain(results):
    df = load_frame(results)
    out = advise(df, 0.01, 10.0)
    assert out["found"] and out["seconds"] == pytest.approx(2.0) and out["kernel"] == "wendland-c2"
    assert out["domain"] == "strip" and out["paper_seconds"] == pytest.approx(50.0)  # not the full domain's 900
    assert out["speedup_over_paper"] == pytest.approx(25.0)
    assert "--kernel wendland-c2" in out["command"] and "--strip-height 4" in out["command"]
    assert 0 < out["stable_cfl"] and out["cfl_fraction"] == pytest.approx(2.5 / out["stable_cfl"])
    full = advise(df, 0.01, 10.0, domain="full")
    assert full["seconds"] == pytest.approx(30.0) and full["paper_seconds"] == pytest.approx(900.0)


def test_lagrangian_is_judged_against_its_own_limit(results):
    out = advise(load_frame(results), 0.0125, 10.0, model="lagrangian")
    assert out["error_against"] == "the isothermal solution"
    assert out["seconds"] == pytest.approx(3.0) and out["paper_seconds"] == pytest.approx(80.0)
    assert advise(load_frame(results), 0.0105, 10.0, model="lagrangian")["found"] is False


def test_advise_command_json_and_what_no_run_reaches(results, capsys):
    rc, out, err = cli_main(
        "advise", "--error", "0.01", "--results", str(results), "--machine", "m", "--json", capsys=capsys
    )
    assert rc == 0, err
    data = json.loads(out)
    assert {"command", "error", "seconds", "paper_seconds"} <= set(data)
    rc, out, err = cli_main(
        "advise", "--error", "0.02", "--t-end", "5", "--results", str(results), "--machine", "m", capsys=capsys
    )
    assert rc == 1 and "none of the 0 stored runs" in out and "pcabench study" in out
    rc, out, err = cli_main("advise", "--error", "2", "--results", str(results), capsys=capsys)
    assert rc == 2 and "--error" in err and "Traceback" not in err
    rc, out, err = cli_main("advise", "--error", "0.02", "--t-end", "-3", "--results", str(results), capsys=capsys)
    assert rc == 2 and "--t-end" in err and "> 0" in err and not out


def test_advise_takes_a_machine_prefix_as_runs_does(results, capsys):
    other = results / store.store_name("mach-two", "h")
    for r in store.read_rows(results):
        store.append(dict(r, profile_id="mach-two", run_id=r["run_id"] + "-2"), other)
    for given, meant in (("mach", "mach-two"), ("m", "m")):  # a prefix of one machine; an exact name wins
        rc, out, err = cli_main(
            "advise", "--error", "0.01", "--results", str(results), "--machine", given, "--json", capsys=capsys
        )
        assert rc == 0 and json.loads(out)["machine"] == meant, err
    rc, out, err = cli_main("advise", "--error", "0.01", "--results", str(results), "--machine", "zz", capsys=capsys)
    assert rc == 2 and "--machine 'zz'" in err and len(err.strip().splitlines()) == 1


def test_a_host_whose_runs_do_not_answer_is_answered_from_a_machine_whose_do(results, capsys, monkeypatch):
    """Issue 66: a new host (no rows) or one whose rows miss the error is answered from the machine whose rows
    reach it, named as the answer's machine and in words; this host's rows win where they answer."""
    from pcabench.machine import profiles

    here = results / store.store_name("this-host", "h")
    _row(here, 0.5, 0.05, kernel="wendland-c4", h_factor=1.3, cfl=1.0)  # this host's one run: not accurate enough
    for r in store.read_rows(here):
        store.append(dict(r, profile_id="this-host", run_id=r["run_id"] + "-h"), here)
    for host in ("this-host", "fresh-host-1"):
        monkeypatch.setenv(profiles.MACHINE_ID_ENV, host)
        profiles.machine_id.cache_clear()
        rc, out, err = cli_main("advise", "--error", "0.01", "--results", str(results), "--json", capsys=capsys)
        data = json.loads(out)
        assert rc == 0 and data["machine"] == "m" and data["host_machine"] == host and data["seconds"] == 2.0, err
        rc, out, err = cli_main("advise", "--error", "0.01", "--results", str(results), capsys=capsys)
        assert rc == 0 and f"this host is {host}, whose stored runs do not answer" in out and "on m:" in out
        rc, out, err = cli_main("advise", "--error", "0.06", "--results", str(results), "--json", capsys=capsys)
        data = json.loads(out)
        assert rc == 0 and data["machine"] == (host if host == "this-host" else "m"), out  # its own rows answer
        assert ("host_machine" in data) is (host != "this-host")
    profiles.machine_id.cache_clear()


def _refuse(name):
    raise ValueError(f"not strict JSON: {name}")


def test_a_run_past_its_predicted_stable_cfl_is_never_advised(results, capsys):
    df = load_frame(results)
    out = advise(df, 0.01, 10.0)
    assert out["found"] and out["cfl"] == 2.5 and out["cfl"] < out["stable_cfl"]  # not the 0.5 s run at CFL 3
    assert out["cfl_fraction"] == pytest.approx(2.5 / out["stable_cfl"]) and out["cfl_fraction"] < 1
    (past,) = out["not_advised"]  # named beside the advice, as unstable by prediction
    assert past["cfl"] == 3.0 and past["stable_cfl"] == pytest.approx(2.354, abs=1e-3) and past["e_foldings"] > 0
    rc, text, err = cli_main("advise", "--error", "0.01", "--results", str(results), "--machine", "m", capsys=capsys)
    assert rc == 0, err
    assert f"CFL 2.5 = {2.5 / out['stable_cfl']:.2f} of the predicted stable {out['stable_cfl']:.3g}" in text
    assert "unstable by prediction" in text and "CFL 3 is past the predicted stable 2.35" in text
    assert ".py" not in text  # no file paths in the explanation
    # only the run past its limit reaches 0.0015: nothing is advised, in text and in JSON (exit 1 both)
    rc, text, _ = cli_main("advise", "--error", "0.0015", "--results", str(results), "--machine", "m", capsys=capsys)
    assert rc == 1 and "within the margin of its stable CFL" in text and "CFL 3 is past" in text and ".py" not in text
    rc, text, _ = cli_main(
        "advise", "--error", "0.0015", "--results", str(results), "--machine", "m", "--json", capsys=capsys
    )
    data = json.loads(text, parse_constant=_refuse)
    assert rc == 1 and data["found"] is False and data["not_advised"][0]["cfl"] == 3.0


def test_advise_json_is_strict_and_the_paper_configuration_is_not_compared_with_itself(results, capsys):
    rc, text, _ = cli_main(
        "advise",
        "--error",
        "0.0115",
        "--model",
        "lagrangian",
        "--results",
        str(results),
        "--machine",
        "m",
        capsys=capsys,
    )
    assert rc == 0 and "this is the paper's configuration" in text and "slower" not in text, text
    assert text.count("pcabench run ") == 1, text  # the command once, not twice with "1x"
    rc, text, _ = cli_main(
        "advise",
        "--error",
        "0.0115",
        "--model",
        "lagrangian",
        "--results",
        str(results),
        "--machine",
        "m",
        "--json",
        capsys=capsys,
    )
    data = json.loads(text, parse_constant=_refuse)
    assert rc == 0 and data["is_paper_configuration"] is True and data["strip_height"] == 4.0
    rc, text, _ = cli_main(
        "advise",
        "--error",
        "0.01",
        "--domain",
        "full",
        "--results",
        str(results),
        "--machine",
        "m",
        "--json",
        capsys=capsys,
    )
    data = json.loads(text, parse_constant=_refuse)  # a full-domain run: its strip height is null, never NaN
    assert rc == 0 and data["strip_height"] is None
    assert data["stable_cfl"] == float(f"{data['stable_cfl']:.3g}") and data["cfl_fraction"] == round(
        data["cfl_fraction"], 2
    )  # rounded as the text prints them


def test_a_moving_model_past_its_long_run_limit_is_never_advised(tmp_path, capsys):
    from pcabench.predict import stability

    path = tmp_path / "results" / store.store_name("m", "h")
    path.parent.mkdir()
    # the paper's method at CFL 4.85: under the periodic lattice's predicted 4.97, past the 4.8 at which long runs
    # on the paper's scene blew up (its free ends)
    _row(path, 0.5, 0.05, model="lagrangian", mse_isothermal=0.009, cfl=4.85)
    _row(path, 80.0, 0.09, model="lagrangian", mse_isothermal=0.0095)
    a = stability.assess({"model": "lagrangian", "cfl": 4.85, "dx": 0.2})
    assert a["past_limit"] and a["limit_from"] == "long runs" and a["stable_cfl"] == 4.8
    # on the periodic 2D pulse the lagrangian model's limit is the prediction's; fixed blew up from 4.75 there
    assert not stability.assess({"scene": "acoustic-pulse", "model": "lagrangian", "cfl": 4.85})["past_limit"]
    assert stability.assess({"scene": "acoustic-pulse", "model": "fixed", "cfl": 4.8})["past_limit"]
    out = advise(load_frame(path.parent), 0.01, 10.0, model="lagrangian")
    assert out["seconds"] == pytest.approx(80.0) and out["not_advised"][0]["cfl"] == 4.85
    rc, text, _ = cli_main(
        "advise", "--error", "0.01", "--model", "lagrangian", "--results", str(path.parent), capsys=capsys
    )
    assert rc == 0 and "CFL 4.85 is past the stable 4.8 measured over long runs" in text, text


@pytest.mark.tier2
@pytest.mark.parametrize(
    "problem",
    [
        ("--open", "x"),  # an open scene: the front takes no --open, so "run study --front" looped
        ("--mach", "0.1", "--domain", "full"),  # another amplitude, on the full domain: no --strip suggested
    ],
    ids=["open-x", "mach-full"],
)
def test_each_command_advise_names_run_gives_advise_what_it_asked_for(tmp_path, problem, capsys):
    """Advice that closes the loop (issue 59): with nothing stored, advise names the study that makes the runs it
    asks about; run as printed, advise then answers from them (and names the margin it kept)."""
    import shlex
    import subprocess
    import sys

    results = tmp_path / "results"
    asked = ("advise", "--error", "0.05", "--t-end", "10", *problem, "--results", str(results))
    rc, _, err = cli_main(*asked, capsys=capsys)
    assert rc == 4 and "run `pcabench study" in err, err
    words = shlex.split(err.split("`")[1])
    for option in problem[::2]:
        if option != "--domain":
            assert option in words  # the problem asked about is the problem run
    assert ("--strip" in words) == ("full" not in problem)
    words = words[words.index("study") + 1 :]
    if "--dx" in words:  # the suggestion's own dx (the finer one is a convergence check: not needed to answer)
        words = words[: words.index("--dx") + 2] + [w for w in words[words.index("--dx") + 2 :] if w.startswith("-")]
    proc = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "study", *words, "--no-report", "--results", str(results)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    rc, text, err = cli_main(*asked, capsys=capsys)
    assert rc == 0, text + err
    assert "fastest:" in text and "advised at most 0.9 of the stable CFL for linear" in text


@pytest.mark.parametrize(
    "args, option",
    [
        (("--mach", "-1"), "--mach"),
        (("--mach", "0.5"), "--mach"),
        (("--open", "y"), "--open y"),  # the plane pulse's y is a plane wave's period
        (("--scene", "cylinder", "--open", "x"), "--open"),  # its four edges are always open
        (("--scene", "cylinder", "--domain", "strip"), "--domain strip"),  # the cylinder has no strip
    ],
)
def test_a_problem_the_scene_refuses_is_refused_before_any_advice(tmp_path, args, option, capsys):
    """A study advise would name for it would be refused in turn: one line naming the option, exit 2, no search."""
    rc, out, err = cli_main("advise", "--error", "0.05", *args, "--results", str(tmp_path), capsys=capsys)
    assert rc == 2 and option in err and len(err.strip().splitlines()) == 1 and not out, err
