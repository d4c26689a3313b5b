"""The paper's published numbers, converted once to the report's units, each with its source and conversion.

From hardware_profiles/paper-system-*.json. A step time is ms per step; a whole
run is divided by its own step count, once, here (:func:`per_step_ms`):

- Table 4: the K20c's stage times of a one-step run, ms: a step is SNP + PI + SU, no conversion.
- Table 6: whole runs of 100 steps on three systems, printed as min; read as s (Table 4 makes seconds
  the consistent reading), / 100 steps.
- Fig. 9 text: whole runs, s, to the 10th step ("based on the results of the 10th timestep"), / 10 steps.
- Text of 5.3: the serial CPU and the K20c step at 400K, ms, no conversion.

Every CPU number is one serial core (the paper's CPU codes are single-thread), and every code but
Fig. 9's all-pair one uses the linked list; all ran in double precision.
"""

from __future__ import annotations

from functools import lru_cache

from pcabench.machine import profiles

SYSTEMS = ("paper-system-1", "paper-system-2", "paper-system-3")
TABLE6_STEPS = 100  # Table 6's "Number of timesteps"
FIG9_STEPS = 10  # Fig. 9: "the comparisons are based on the results of the 10th timestep"
CONVERSION = {
    "Table 4": "one step, ms",
    "Table 6": "run / 100 steps, printed min read as s",
    "Fig. 9 text": "run / 10 steps",
    "text, 400K": "one step, ms",
}


def per_step_ms(run_seconds: float, steps: int) -> float:
    """A whole run's time (s) as ms per step: the one conversion of the paper's run times."""
    return 1e3 * run_seconds / steps


@lru_cache(maxsize=None)
def _profile(system: str) -> dict:
    return profiles.load(system)


def published(system: str = "paper-system-1") -> dict:
    """The raw published numbers of ``system`` (its profile's ``published``)."""
    return _profile(system)["published"]


def processor(system: str, device: str) -> str:
    """The paper's CPU model or GPU card of ``system``."""
    return _profile(system)["cpu" if device == "cpu" else "gpu"].get("model" if device == "cpu" else "name", system)


@lru_cache(maxsize=None)
def step_times() -> tuple[dict, ...]:
    """Every published step time: system, device (cpu/gpu), processor, search (linked list/all-pair), N, ms,
    source and conversion. Serial CPU, double precision throughout."""
    rows = []
    one = published()
    for n, stages in one["table4"]["rows"].items():
        rows.append(_row("paper-system-1", "gpu", "linked list", n, sum(stages[2:5]), "Table 4"))
    for system in SYSTEMS:
        for n, (cpu, gpu, _speedup) in published(system)["table6"]["rows"].items():
            rows.append(_row(system, "cpu", "linked list", n, per_step_ms(cpu, TABLE6_STEPS), "Table 6"))
            rows.append(_row(system, "gpu", "linked list", n, per_step_ms(gpu, TABLE6_STEPS), "Table 6"))
    text = one["text"]
    for device, ms in text["cpu_vs_gpu_step_400k_ms"].items():
        rows.append(_row("paper-system-1", device, "linked list", 400_000, ms, "text, 400K"))
    for search, key in (("all-pair", "fig9_allpair_s"), ("linked list", "fig9_linkedlist_s")):
        for n, seconds in text[key].items():
            rows.append(_row("paper-system-1", "cpu", search, n, per_step_ms(seconds, FIG9_STEPS), "Fig. 9 text"))
    return tuple(sorted(rows, key=lambda r: (r["device"], r["search"], r["source"], r["system"], r["N"])))


def _row(system, device, search, n, ms, source) -> dict:
    return {
        "system": system,
        "device": device,
        "processor": processor(system, device),
        "search": search,
        "N": int(n),
        "ms": ms,
        "source": source,
        "conversion": CONVERSION[source],
    }


def same_kind(device: str, search: str, n: int) -> list[dict]:
    """The published step times of one device and search at ``n`` particles (several sources may hold one)."""
    return [r for r in step_times() if (r["device"], r["search"], r["N"]) == (device, search, int(n))]


def table4() -> dict[int, list[float]]:
    """The K20c's stage times (input, init, SNP, PI, SU, output; ms, one-step runs) by N."""
    return {int(n): v for n, v in sorted(published()["table4"]["rows"].items(), key=lambda kv: int(kv[0]))}


def table5() -> dict[int, list[float]]:
    """The K20c's shares of a step (SNP, PI, SU; %) by N."""
    return {int(n): v for n, v in sorted(published()["table5"]["rows"].items(), key=lambda kv: int(kv[0]))}


def cpu_shares() -> dict:
    """The serial linked-list CPU's shares of a step (Fig. 11's text: about 43 % SNP, 53 % PI; SU the rest)."""
    s = published()["text"]["fig11_cpu_step_shares_pct"]
    return {"snp": s["snp"], "pi": s["pi"], "su": 100 - s["snp"] - s["pi"]}


def table6() -> list[dict]:
    """Table 6 as printed (runtimes in its unit, min as printed, read as s) with its speedup per step."""
    rows = []
    for system in SYSTEMS:
        for n, (cpu, gpu, speedup) in published(system)["table6"]["rows"].items():
            rows.append(
                {
                    "system": system,
                    "card": processor(system, "gpu"),
                    "N": int(n),
                    "cpu": cpu,
                    "gpu": gpu,
                    "speedup": speedup,
                }
            )
    return sorted(rows, key=lambda r: (r["system"], r["N"]))


def fig8_point() -> tuple[float, float]:
    """Fig. 8's published error: (dx, relative RMS) at the paper's finest lattice after 100 steps."""
    return 0.004, published()["text"]["fig8_mse_100_steps_dx_0.004"]
