"""softarm.sweep against the CLI's `softarm sweep`: the same grid gives the
same rows, values and figures (to the 13 digits sweep.csv prints), run
locally in processes and on a Dask LocalCluster of two worker processes."""

import pandas as pd
import pytest

import softarm
from test_api import run

VARY = {"segment.0.youngs_modulus": "log:5e5:2e6:3", "tip.mass": [0, 0.01]}
CLI_VARY = ["--vary", "segment.0.youngs_modulus=log:5e5:2e6:3", "--vary", "tip.mass=0,0.01"]


def cli_sweep(tmp_path, study, *extra):
    out = tmp_path / study
    run("sweep", "soft_finger", "--run", study, *CLI_VARY, *extra, "--out", str(out), "--quiet")
    return pd.read_csv(out / "sweep.csv", dtype={k: str for k in VARY})


def same(ours, ref):
    assert list(ours.columns) == list(ref.columns)
    for k in VARY:
        assert [float(v) for v in ours[k]] == [float(v) for v in ref[k]]
    assert list(ours["status"]) == list(ref["status"])
    for col in ref.columns:
        if col in ("run", "status", "wall_s", "run_wall_s", *VARY):
            continue
        for a, b in zip(ours[col], ref[col]):
            assert abs(a - b) <= 1e-12 * max(abs(b), 1e-300), (col, a, b)


def test_a_local_sweep_is_the_clis(tmp_path):
    same(softarm.sweep("soft_finger", VARY, run="modes", jobs=2), cli_sweep(tmp_path, "modes"))
    same(softarm.sweep("soft_finger", VARY, run="simulate", t_end=0.2, jobs=2),
         cli_sweep(tmp_path, "simulate", "--t-end", "0.2", "--shape-points", "0"))


def test_varied_values_are_numbers_that_sort_as_numbers():
    df = softarm.sweep("soft_finger", {"segment.0.youngs_modulus": [1e6, 2e5]}, run="static",
                       jobs=1)
    column = df["segment.0.youngs_modulus"]
    assert column.dtype.kind == "f"
    assert list(column.sort_values()) == [2e5, 1e6]


def test_a_dask_sweep_is_the_clis(tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        df = softarm.sweep("soft_finger", VARY, run="static", client=client)
    same(df, cli_sweep(tmp_path, "static"))


def test_a_failed_run_is_a_row():
    df = softarm.sweep("soft_finger", {"segment.0.length": [0.12, -1.0]}, run="static", jobs=1)
    assert df["status"][0] == "ok"
    assert df["status"][1].startswith("failed:") and "length" in df["status"][1]


def test_an_interrupted_sweep_returns_what_finished(monkeypatch):
    """Ctrl-C (KeyboardInterrupt in the main thread) after two runs have
    finished: their rows as an uninterrupted sweep has them, the others
    `not run`, listed in attrs and warned about."""
    import concurrent.futures

    real = concurrent.futures.as_completed

    def two_then_ctrl_c(futures, *a, **k):
        for n, f in enumerate(real(futures, *a, **k)):
            if n == 2:
                raise KeyboardInterrupt
            yield f

    vary = {"tip.mass": [0, 0.005, 0.01, 0.015, 0.02, 0.025]}
    whole = softarm.sweep("soft_finger", vary, run="static", jobs=1)
    monkeypatch.setattr(concurrent.futures, "as_completed", two_then_ctrl_c)
    with pytest.warns(UserWarning, match="4 of 6 runs did not finish"):
        df = softarm.sweep("soft_finger", vary, run="static", jobs=1)
    done = [k for k in range(6) if df["status"][k] == "ok"]
    assert len(done) == 2 and sorted(df.attrs["unfinished"]) == [k for k in range(6) if k not in done]
    for k in df.attrs["unfinished"]:
        assert df["status"][k] == "not run: interrupted (Ctrl-C)"
    for k in done:
        assert df["tip_x"][k] == whole["tip_x"][k] and df["tip_y"][k] == whole["tip_y"][k]
