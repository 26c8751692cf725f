"""Parameter sweeps from Python (`softarm.sweep`): the grid of ``softarm sweep``, run in
parallel here or as tasks on a Dask cluster.

    import softarm
    df = softarm.sweep("soft_finger", vary={"segment.0.youngs_modulus": "log:5e5:2e6:5",
                                            "tip.mass": [0, 0.01]}, run="modes")

The combinations, their value strings and the figures are the CLI's: the
grid comes from the same Rust code (`softarm::grid`) and every run goes
through the same core, so the DataFrame has ``sweep.csv``'s columns and
values (wall times aside). A task carries only the model's name or path,
its overrides and the run's options; each worker loads the compiled core
itself.
"""

from __future__ import annotations

import json
import os
import time
import warnings
from typing import Any, Mapping, Optional, Sequence, Union

from . import _softarm

Values = Union[str, Sequence[Any]]


def _spec(path: str, values: Values) -> str:
    if isinstance(values, str):
        return f"{path}={values}"
    text = ",".join(v if isinstance(v, str) else json.dumps(v) for v in values)
    return f"{path}={text}"


def _tip(tip) -> list:
    return [(name, float(v)) for name, v in zip(("tip_x", "tip_y", "tip_z"), tip)]


def run_one(model: str, sets: Sequence[str], run: str, options: Mapping[str, Any]) -> dict:
    """One combination: its status, wall time and figures (as the CLI's
    `sweep.csv` names them). A failure is a status, never an exception."""
    import softarm  # in the worker

    started = time.perf_counter()
    figures: list = []
    status = "ok"
    try:
        overrides = dict(s.split("=", 1) for s in sets)
        m = softarm.load(model, set=overrides)
        if run == "simulate":
            try:
                r = m.simulate(**options)
                figures = _tip(r["tip"][-1])
                err = r["summary"].get("tip_error")
                if err:
                    figures.append(("tip_error_mean_mm", 1e3 * err["mean_m"]))
                figures.append(("run_wall_s", r["summary"]["wall_s"]))
            except softarm.IntegrationError as e:
                status = f"failed: {e.report.get('reason', str(e))}"
        elif run == "static":
            figures = _tip(m.static(options.get("q0"))["tip"])
        elif run == "modes":
            f = m.modes(options.get("q0"))["frequencies_hz"]
            figures = [(f"f{k + 1}_hz", float(x)) for k, x in enumerate(f[:3])]
        else:
            raise ValueError(f"run = {run!r}: the runs are simulate, static and modes")
    except Exception as e:  # the row says what went wrong
        status = f"failed: {e}"
    return {"status": status, "wall_s": time.perf_counter() - started, "figures": figures}


def sweep(
    model: str,
    vary: Mapping[str, Values],
    run: str = "simulate",
    figures: Optional[Sequence[str]] = None,
    client: Any = None,
    set: Optional[Mapping[str, Any]] = None,
    jobs: Optional[int] = None,
    yes: bool = False,
    **options: Any,
):
    """Run `run` ("simulate", "static" or "modes") for every combination of
    the `vary` values (a list, or "lin:a:b:n" / "log:a:b:n") and return a
    pandas DataFrame: run, the varied keys, status, wall_s, the figures
    (all, or those named in `figures`). `options` go to `Model.simulate`
    (t_end, solver, rtol, ...). With a `dask.distributed.Client` the runs
    are tasks on its cluster; else they run here on `jobs` processes
    (default: every core). A grid of more than 10,000 runs needs
    `yes=True`. Rows come in as runs finish: Ctrl-C (or a lost worker)
    returns what finished, the other rows `not run: ...` (or `failed:
    its worker was lost ...`), their indices in `df.attrs["unfinished"]`,
    with a warning."""
    import pandas as pd

    specs = [_spec(p, v) for p, v in vary.items()]
    paths, values, combos = _softarm.sweep_grid(specs, yes)
    base = [f"{k}={v if isinstance(v, str) else json.dumps(v)}" for k, v in (set or {}).items()]
    tasks = [base + [f"{p}={values[i][c[i]]}" for i, p in enumerate(paths)] for c in combos]
    rows: list = [None] * len(tasks)
    stopped = _run_all(model, tasks, run, options, client, jobs, rows)
    unfinished = [k for k, r in enumerate(rows) if r is None or r.get("lost")]
    for k in unfinished:
        if rows[k] is None:
            rows[k] = {"status": f"not run: {stopped}", "wall_s": float("nan"), "figures": []}
    if unfinished:
        warnings.warn(f"softarm.sweep: {len(unfinished)} of {len(tasks)} runs did not finish "
                      f"({stopped or 'workers lost'}); their rows say why "
                      "(DataFrame.attrs['unfinished'])",
                      stacklevel=2)
    names: list = []
    for r in rows:
        for n, _ in r["figures"]:
            if n not in names:
                names.append(n)
    if figures is not None:
        names = [n for n in names if n in figures]
    table = []
    for k, (c, r) in enumerate(zip(combos, rows)):
        row = {"run": k}
        row.update({p: _number(values[i][c[i]]) for i, p in enumerate(paths)})
        row["status"] = r["status"].splitlines()[0] if r["status"] else ""
        row["wall_s"] = r["wall_s"]
        got = dict(r["figures"])
        row.update({n: got.get(n, float("nan")) for n in names})
        table.append(row)
    df = pd.DataFrame(table, columns=["run", *paths, "status", "wall_s", *names])
    df.attrs["unfinished"] = unfinished
    return df


def _number(value: str) -> Any:
    """A varied value as the table holds it: a number where it is one (so
    that columns sort and pivot numerically: 200000 before 1000000), else
    its text (an array, a word)."""
    try:
        return float(value)
    except ValueError:
        return value


def _lost(e: BaseException) -> dict:
    """The row of a task that raised instead of returning its row: its
    worker died or was lost (a run's own failure is a row, never raised)."""
    return {"status": f"failed: its worker was lost ({type(e).__name__}: {e})",
            "wall_s": float("nan"), "figures": [], "lost": True}


def _run_all(model, tasks, run, options, client, jobs, rows) -> Optional[str]:
    """Run every task into `rows` as each finishes (a Dask cluster's, or
    local processes). Ctrl-C stops the sweep: the runs not finished are
    cancelled and left None, and the reason is returned."""
    args = [(model, t, run, options) for t in tasks]
    if client is not None:
        from distributed import as_completed

        futures = [client.submit(run_one, *a, pure=False) for a in args]
        index = {f.key: k for k, f in enumerate(futures)}
        try:
            for f in as_completed(futures):
                try:
                    rows[index[f.key]] = f.result()
                except Exception as e:  # noqa: BLE001 - the row says what was lost
                    rows[index[f.key]] = _lost(e)
        except KeyboardInterrupt:
            client.cancel([f for f in futures if not f.done()])
            return "interrupted (Ctrl-C)"
        return None
    from concurrent.futures import ProcessPoolExecutor, as_completed as done

    pool = ProcessPoolExecutor(max_workers=jobs or os.cpu_count())
    try:
        futures = {pool.submit(run_one, *a): k for k, a in enumerate(args)}
        for f in done(futures):
            try:
                rows[futures[f]] = f.result()
            except Exception as e:  # noqa: BLE001 - the row says what was lost
                rows[futures[f]] = _lost(e)
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)
        return "interrupted (Ctrl-C)"
    pool.shutdown()
    return None
