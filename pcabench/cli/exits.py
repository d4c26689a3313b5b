"""The command line's exit codes (each means one thing) and its description."""

from __future__ import annotations

from pcabench.usage import EXIT_BAD_INPUT

DESCRIPTION = """Benchmark SPH solvers of computational acoustics (a Gaussian sound pulse in 2D, the paper's
scene) on CPUs and GPUs: run one scene, sweep studies into a results store, write reports with
tables and figures, and ask which stored run reaches an error fastest (advise) or what error and
largest stable step the dispersion relation predicts (accuracy)."""

# exit codes: each one means one thing
EXIT_OK, EXIT_RUN_FAILED, EXIT_UNAVAILABLE, EXIT_NO_RESULTS, EXIT_INTERRUPTED = 0, 1, 3, 4, 130
EXIT_DISK_FULL = 5  # the store's disk is full (not bad input: free space and rerun)
EXIT_PIPE, EXIT_TERMINATED = 141, 143  # 128 + SIGPIPE (the reader of stdout left: `| head`), 128 + SIGTERM
EXIT_HELP = f"""exit codes:
  {EXIT_OK}    ok
  {EXIT_RUN_FAILED}    the run failed: unstable (with its step), out-of-memory or error, recorded, never a
       traceback; `advise`: no stored run reaches --error; `gpu-check`: a stage failed
  {EXIT_BAD_INPUT}    bad input: one line naming the parameter and its allowed range, before any work
  {EXIT_UNAVAILABLE}    the solver cannot run here (no GPU)
  {EXIT_NO_RESULTS}    no results: no stored runs to report or advise from (run `pcabench study` first)
  {EXIT_DISK_FULL}    the results store's disk is full: every finished run is kept; free space and rerun to resume
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C); {EXIT_TERMINATED}: terminated (SIGTERM); {EXIT_PIPE}: the reader of the
       output left (`| head`), silently. A sweep stopped either way keeps every finished run and resumes"""
