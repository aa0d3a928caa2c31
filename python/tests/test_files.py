"""The Python API writes what the CLI writes: map, sweep and reproduce with
``out`` and ``shard``, ``merge``, ``slurm`` (its scripts run here without
SLURM), ``simulate(out=)``, ``plot``, and ``out`` of cycle, hb, branch and
stability. Files are compared byte for byte with the CLI's (or with the
unsharded study's, which the CLI's own tests tie to the CLI)."""

import filecmp
import json
import os
import subprocess

import numpy as np
import pytest

import squeal

GRID = dict(x=("V", 1.0, 10.0, 5), y=("N", 500.0, 2000.0, 4))
CLI_GRID = ["--x", "V=1:10:5", "--y", "N=500:2000:4"]


def same(a, b, names):
    for n in names:
        assert filecmp.cmp(a / n, b / n, shallow=False), n


def test_map_out_is_the_clis_and_shards_merge_into_it(cli, tmp_path):
    cli("map", "disc-pad", *CLI_GRID, "--out", str(tmp_path / "cli"))
    whole = squeal.map("disc-pad", **GRID, out=tmp_path / "py")
    same(tmp_path / "cli", tmp_path / "py", ["map.csv", "map.png", "map.svg"])
    assert whole.attrs["out"] == str(tmp_path / "py")
    parts = [squeal.map("disc-pad", **GRID, shard=(k, 3), out=tmp_path / f"s{k}") for k in range(3)]
    assert [p["points"] for p in parts] == [7, 7, 6]
    assert all(p["grid_points"] == 20 and p["shards"] == 3 for p in parts)
    # The CLI merges the Python shards, and Python merges them: both the unsharded map.
    cli("merge", *(str(tmp_path / f"s{k}") for k in range(3)), "--out", str(tmp_path / "cm"))
    merged = squeal.merge([tmp_path / f"s{k}" for k in (2, 0, 1)], out=tmp_path / "pm")
    same(tmp_path / "cli", tmp_path / "cm", ["map.csv", "map.png"])
    same(tmp_path / "cli", tmp_path / "pm", ["map.csv", "map.png", "map.svg"])
    for v in ("max_growth_rate", "freq_hz"):
        np.testing.assert_array_equal(merged[v].values, whole[v].values)
        assert merged[v].attrs == whole[v].attrs
    assert merged["V"].attrs == {"units": "m/s", "long_name": "parameter V"}


def test_merge_refuses_a_missing_shard_naming_its_points(tmp_path):
    for k in (0, 2):
        squeal.map("disc-pad", **GRID, shard=(k, 3), out=tmp_path / f"s{k}")
    with pytest.raises(squeal.ScenarioError, match=r"missing shard 1/3 \(points 1, 4, 7"):
        squeal.merge([tmp_path / "s0", tmp_path / "s2"], out=tmp_path / "m")
    assert not (tmp_path / "m").exists()
    with pytest.raises(squeal.ScenarioError, match=r"^shard 3/3: K counts from 0"):
        squeal.map("disc-pad", **GRID, shard=(3, 3), out=tmp_path / "x")
    with pytest.raises(squeal.ScenarioError, match="expected \\(K, N\\)"):
        squeal.map("disc-pad", **GRID, shard=3, out=tmp_path / "x")  # type: ignore[arg-type]


def test_sweep_shards_merge_into_the_clis_sweep(cli, tmp_path):
    cli("sweep", "hoffmann", "--param", "mu=0.1:0.5:21", "--out", str(tmp_path / "cli"))
    whole = squeal.sweep("hoffmann", param=("mu", 0.1, 0.5, 21), out=tmp_path / "py")
    same(tmp_path / "cli", tmp_path / "py", ["sweep.csv", "sweep.png"])
    parts = [squeal.sweep("hoffmann", param=("mu", 0.1, 0.5, 21), shard=(k, 2), out=tmp_path / f"s{k}") for k in range(2)]
    assert (parts[1]["first"], parts[1]["computed_from"], parts[1]["values"]) == (10, 8, 11)
    merged = squeal.merge([tmp_path / "s1", tmp_path / "s0"], out=tmp_path / "m")
    same(tmp_path / "cli", tmp_path / "m", ["sweep.csv", "sweep.png", "sweep.svg"])
    np.testing.assert_array_equal(merged["eigenvalue"].values, whole["eigenvalue"].values)
    assert merged.attrs["onset_value"] == whole.attrs["onset_value"]


def test_reproduce_shards_merge_into_the_whole_report(tmp_path):
    whole = squeal.reproduce(duration_scale=0.02, figures=False, out=tmp_path / "w")
    parts = [squeal.reproduce(duration_scale=0.02, figures=False, shard=(k, 2), out=tmp_path / f"s{k}") for k in range(2)]
    assert [r["set"] for r in parts[1]["sets"]] == [str(i) for i in range(2, 41, 2)]
    assert parts[0]["conclusions"] == []
    merged = squeal.merge([tmp_path / "s0", tmp_path / "s1"], out=tmp_path / "m")
    same(tmp_path / "w", tmp_path / "m", ["table.csv", "conclusions.json", "report.md", "report.html", "map.png"])
    assert merged["table_csv"] == whole["table_csv"]
    assert merged["conclusions"] == whole["conclusions"]
    assert [c["id"] for c in merged["conclusions"]] == list(range(1, 8))


def test_slurm_scripts_run_without_slurm_and_merge_into_the_map(tmp_path):
    # A dict scenario travels as scenario.json in the jobs folder; each array
    # task and the merge job run `python -m squeal`.
    sc = squeal.scenario("disc-pad")
    r = squeal.slurm("map", sc, tasks=3, **GRID, out=tmp_path / "merged", partition="short", time="0:10:00", N=1000)
    assert r["jobs"] == str(tmp_path / "merged-slurm")
    array = open(r["array"]).read()
    assert "#SBATCH --array=0-2" in array and "#SBATCH --partition=short" in array
    assert f"{r['jobs']}/scenario.json --set N=1000" in array
    assert r["submit_line"].startswith("ARRAY=$(sbatch --parsable ")
    for k in range(3):
        env = {**os.environ, "SLURM_ARRAY_TASK_ID": str(k)}
        subprocess.run(["bash", r["array"]], env=env, check=True, capture_output=True)
    subprocess.run(["bash", r["merge"]], check=True, capture_output=True)
    squeal.map(sc, **GRID, out=tmp_path / "whole", N=1000)
    same(tmp_path / "whole", tmp_path / "merged", ["map.csv", "map.png"])


def test_slurm_refuses_bad_jobs_in_one_line(tmp_path):
    with pytest.raises(squeal.ScenarioError, match="--tasks 21: more tasks than the 20 points"):
        squeal.slurm("map", tasks=21, **GRID, out=tmp_path / "m")
    with pytest.raises(squeal.ScenarioError, match="--partition"):
        squeal.slurm("map", tasks=2, **GRID, out=tmp_path / "m", partition="a\nb")
    with pytest.raises(squeal.ScenarioError, match='study "cycle": expected'):
        squeal.slurm("cycle", tasks=2, out=tmp_path / "m")
    assert not any(tmp_path.iterdir())


def test_python_m_squeal_exits_2_on_bad_input(tmp_path):
    import sys

    p = subprocess.run(
        [sys.executable, "-m", "squeal", "map", "disc-pad", "--x", "V=1:2", "--y", "N=1:2:3", "--out", str(tmp_path / "o")],
        capture_output=True, text=True,
    )
    assert p.returncode == 2 and p.stderr.strip() == "error: --x V=1:2: expected NAME=LO:HI:N"
    assert not (tmp_path / "o").exists()


def test_simulate_out_writes_the_clis_run_folder_and_plot_redraws_it(cli, tmp_path):
    cli("simulate", "disc-pad", "--set", "duration=0.05", "--out", str(tmp_path / "cli"))
    run = squeal.simulate("disc-pad", duration=0.05, out=tmp_path / "py")
    assert run.out == str(tmp_path / "py")
    same(tmp_path / "cli", tmp_path / "py", ["series.csv", "events.csv", "spectrum.csv"])
    a = json.loads((tmp_path / "cli" / "summary.json").read_text())
    b = json.loads((tmp_path / "py" / "summary.json").read_text())
    a.pop("timing"), b.pop("timing")
    assert a == b and run.summary["verdict"] == a["verdict"]
    assert {"triplet.png", "spectrogram.png"} <= set(os.listdir(tmp_path / "py"))
    cli("plot", str(tmp_path / "cli"), "--fmax", "3000")
    squeal.plot(tmp_path / "py", fmax=3000.0)
    same(tmp_path / "cli", tmp_path / "py", ["spectrum.csv", "triplet.png", "spectrogram.png"])
    with pytest.raises(squeal.ScenarioError, match="--fmax and --frange"):
        squeal.plot(tmp_path / "py", fmax=3000.0, frange=(10.0, 20.0))


def test_cycle_hb_branch_and_stability_write_the_clis_files(cli, tmp_path):
    cli("cycle", "hoffmann", "--out", str(tmp_path / "c_cli"))
    c = squeal.cycle("hoffmann", out=tmp_path / "c_py")
    assert c["out"] == str(tmp_path / "c_py")
    same(tmp_path / "c_cli", tmp_path / "c_py", ["orbit.csv", "summary.json", "cycle.png"])
    cli("hb", "hoffmann", "--harmonics", "8", "--out", str(tmp_path / "h_cli"))
    squeal.hb("hoffmann", harmonics=8, out=tmp_path / "h_py")
    same(tmp_path / "h_cli", tmp_path / "h_py", ["hb_orbit.csv", "hb.png"])
    cli("stability", "disc-pad", "--no-levers", "--out", str(tmp_path / "s_cli"))
    st = squeal.stability("disc-pad", levers=False, out=tmp_path / "s_py")
    assert st.out == str(tmp_path / "s_py")
    same(tmp_path / "s_cli", tmp_path / "s_py", ["modes.csv"])
    # A folder squeal did not write is never replaced.
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine")
    with pytest.raises(squeal.ScenarioError, match="notes.txt"):
        squeal.cycle("hoffmann", out=tmp_path / "mine")
    assert (tmp_path / "mine" / "notes.txt").read_text() == "mine"
