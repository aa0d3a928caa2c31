"""The Python package against the CLI's own outputs (exact: same bits), its
shapes, dtypes and errors, determinism over threads, and Ctrl-C."""

import csv
import json
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import squeal

SHORT = 0.05  # s: a short run still crosses stick-slip events at these settings


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    assert a.shape == b.shape, (a.shape, b.shape)
    np.testing.assert_array_equal(a.view(np.uint64), b.view(np.uint64))


def test_simulate_equals_cli_series_bits_and_summary(cli, tmp_path):
    out = tmp_path / "run"
    cli("simulate", "disc-pad", "--set", "N=2000", "--set", "V=2.5", "--duration", str(SHORT),
        "--format", "npy", "--no-plots", "--out", str(out))
    series = np.load(out / "series.npy")
    run = squeal.simulate("disc-pad", duration=SHORT, N=2000, set={"V": 2.5})
    same_bits(run.data, series)
    cli_summary = json.loads((out / "summary.json").read_text())
    for d in (cli_summary, run.summary):
        d.pop("timing", None)
        d.pop("audio", None)
    assert run.summary == cli_summary
    events = (out / "events.csv").read_text().splitlines()[1:]
    assert len(events) == len(run.events["t"])
    for line, t, k, c in zip(events, run.events["t"], run.events["kind"], run.events["contact"]):
        ct, ck, cc = line.split(",")
        assert (float(ct), ck, cc) == (t, k, c)


def test_run_shapes_dtypes_and_columns():
    run = squeal.simulate(duration=SHORT)
    assert run.data.dtype == np.float64 and run.data.ndim == 2
    assert run.data.shape == (len(run.t), len(run.columns))
    assert run.columns[0] == "t" and "vx_p" in run.columns
    assert run.t.dtype == np.float64 and run.t[0] == 0.0
    np.testing.assert_allclose(run.t[-1], SHORT)
    assert run["vx_p"].shape == run.t.shape
    assert np.shares_memory(run["vx_p"], run.data)  # a view, no copy
    assert run.events["t"].dtype == np.float64
    assert run.events["kind"].shape == run.events["contact"].shape == run.events["t"].shape
    # One of the judge's words (README, "The verdict: one word per run").
    assert run.summary["verdict"] in (
        "out-of-range", "lift-off", "grows", "limit-cycle", "stick-slip",
        "decays", "too-short", "neutral",
    ), run.summary["verdict"]
    f, p = run.spectra["vx_p"]
    assert f.shape == p.shape and f.dtype == p.dtype == np.float64
    with pytest.raises(KeyError, match="nope"):
        run["nope"]


def test_to_pandas_and_to_xarray():
    run = squeal.simulate(duration=SHORT)
    pd = pytest.importorskip("pandas")
    df = run.to_pandas()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == run.columns[1:]
    same_bits(df["vx_p"].to_numpy(), run["vx_p"])
    xr = pytest.importorskip("xarray")
    ds = run.to_xarray()
    assert isinstance(ds, xr.Dataset)
    same_bits(ds["vx_p"].values, run["vx_p"])


def test_stability_equals_cli_json_bits(cli):
    doc = json.loads(cli("stability", "disc-pad", "--set", "V=2", "--json"))
    st = squeal.stability("disc-pad", V=2.0)
    cli_eig = np.array([complex(e["re"], e["im"]) for e in doc["eigenvalues"]])
    assert st.eigenvalues.dtype == np.complex128
    same_bits(st.eigenvalues.real, cli_eig.real)
    same_bits(st.eigenvalues.imag, cli_eig.imag)
    same_bits(st.frequencies_hz, [e["freq_hz"] for e in doc["eigenvalues"]])
    same_bits(st.damping_ratios, [e["damping_ratio"] for e in doc["eigenvalues"]])
    assert st.to_dict() == doc
    assert st.stable == doc["stable"] and st.least_stable == doc["least_stable"]
    assert st.levers == doc["levers"]


def test_stability_shapes_and_modes():
    st = squeal.stability("disc-pad", levers=False)
    n2 = len(st.eigenvalues)
    n = len(st.dofs)
    assert n2 == 2 * n == 8  # the 4-dof model: all 2n eigenvalues
    assert st.growth_rates.dtype == np.float64 and st.growth_rates.shape == (n2,)
    assert st.modes.shape == (n2, n) and st.modes.dtype == np.complex128
    # The shapes are normalised: the largest position component is exactly 1.
    np.testing.assert_allclose(np.abs(st.modes).max(axis=1), 1.0, rtol=0, atol=1e-15)
    # Amplitudes and phases are those the CLI's JSON lists (NumPy's |z| and
    # angle round differently from Rust's hypot/atan2: to 1 ulp).
    doc = st.to_dict()
    for k, e in enumerate(doc["eigenvalues"]):
        np.testing.assert_allclose(np.abs(st.modes[k]), [s["amplitude"] for s in e["shape"]], rtol=1e-15)
        amp = np.abs(st.modes[k]) > 1e-12
        np.testing.assert_allclose(np.degrees(np.angle(st.modes[k]))[amp],
                                   np.array([s["phase_deg"] for s in e["shape"]])[amp], rtol=1e-13, atol=1e-12)
    assert st.growth_rates[0] == st.growth_rates.max()


def test_map_equals_cli_csv_bits(cli, tmp_path):
    out = tmp_path / "map"
    cli("map", "disc-pad", "--x", "V=0.5:20:7", "--y", "N=100:3000:5", "--out", str(out))
    rows = [line.split(",") for line in (out / "map.csv").read_text().splitlines()[1:]]
    cli_arr = np.array([[float(v) for v in r] for r in rows])
    m = squeal.map("disc-pad", x=("V", 0.5, 20, 7), y=("N", 100, 3000, 5))
    sigma = np.asarray(m["max_growth_rate"])
    assert sigma.shape == (5, 7)
    same_bits(sigma.ravel(), cli_arr[:, 2])
    same_bits(np.asarray(m["freq_hz"]).ravel(), cli_arr[:, 3])
    same_bits(np.asarray(m["V"]), np.unique(cli_arr[:, 0]))
    same_bits(np.asarray(m["N"]), np.unique(cli_arr[:, 1]))


def test_map_is_the_same_with_1_and_2_threads():
    a = squeal.map(x=("V", 0.5, 20, 9), y=("c_px", 0.05, 0.5, 8), threads=1)
    b = squeal.map(x=("V", 0.5, 20, 9), y=("c_px", 0.05, 0.5, 8), threads=2)
    same_bits(a["max_growth_rate"], b["max_growth_rate"])
    same_bits(a["freq_hz"], b["freq_hz"])


def test_map_xarray_coordinates_named_after_parameters():
    xr = pytest.importorskip("xarray")
    ds = squeal.map(x=("V", 1, 10, 4), y=("N", 500, 2000, 3))
    assert isinstance(ds, xr.Dataset)
    assert ds["max_growth_rate"].dims == ("N", "V")
    assert ds["V"].attrs["units"] == "m/s"


def test_transient_map_point_outcomes():
    m = squeal.map(x=("V", 1, 10, 2), y=("N", 500, 2000, 2), transient=True, duration=0.05)
    assert np.asarray(m["outcome"]).shape == (2, 2)
    assert np.asarray(m["agree"]).shape == (2, 2)
    # The disc faces radiate: every squealing point has a level (dB(A)).
    dba = np.asarray(m["spl_dba"])
    assert dba.shape == (2, 2) and np.all(np.isfinite(dba)) and np.all(dba > 60.0)


def test_critical_equals_cli_json(cli):
    doc = json.loads(cli("critical", "disc-pad", "--param", "V=1:16.5", "--json"))
    c = squeal.critical("disc-pad", param=("V", 1.0, 16.5))
    assert c == doc
    assert c["value"] is not None and 1.0 < c["value"] < 16.5


def test_critical_none_when_nothing_crosses(cli):
    doc = json.loads(cli("critical", "disc-pad", "--param", "V=30:40", "--json"))
    c = squeal.critical("disc-pad", param=("V", 30.0, 40.0))
    assert c == doc
    assert (c["param"], c["value"], c["freq_hz"]) == ("V", None, None)


def test_critical_refuses_a_grid_out_of_range():
    for grid in (1, 100_001):
        with pytest.raises(squeal.ScenarioError, match=f"--grid {grid}: must be between 2 and 100000"):
            squeal.critical("hoffmann", param=("mu", 0.0, 1.0), grid=grid)


def test_sweep_is_a_dataset_with_units(cli, tmp_path):
    sw = squeal.sweep(param=("c_px", 0.05, 0.5, 11))
    assert sw["eigenvalue"].shape == (11, 8) and sw["eigenvalue"].dtype == np.complex128
    assert sw["eigenvalue"].dims == ("c_px", "branch")
    assert int(sw["listed"].sum()) == 4
    for name in list(sw.data_vars) + list(sw.coords):
        assert sw[name].attrs["units"] and sw[name].attrs["long_name"], name
    assert sw["c_px"].attrs["units"] == "kg/s" and sw["freq_hz"].attrs["units"] == "Hz"
    np.testing.assert_array_equal(sw["growth_rate"].values, sw["eigenvalue"].values.real)
    # Hoffmann's coalescence: the onsets are the CLI's, to the bit.
    h = squeal.sweep("hoffmann", param=("mu", 0.0, 1.0, 21))
    doc = json.loads(cli("sweep", "hoffmann", "--param", "mu=0:1:21", "--json", "--out", str(tmp_path / "s")))
    assert [o["value"] for o in doc["onsets"]] == h.attrs["onset_value"]
    assert [o["freq_hz"] for o in doc["onsets"]] == h.attrs["onset_freq_hz"]
    assert [o["direction"] for o in doc["onsets"]] == h.attrs["onset_direction"] == ["destabilising"]
    assert h.attrs["onset_coalescence"] == [1]


def test_validate_equals_cli_json(cli):
    doc = json.loads(cli("validate", "hoffmann", "--json"))
    assert squeal.validate("hoffmann") == doc
    assert doc["passed"] == 3 and doc["failed"] == 0
    with pytest.raises(squeal.ScenarioError, match="no validation case's name contains"):
        squeal.validate("no-such-case")


FE_BRAKE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "fe-brake" / "two-pad" / "brake.toml"


def test_inspect_equals_cli_json(cli):
    assert squeal.inspect(FE_BRAKE) == json.loads(cli("inspect", str(FE_BRAKE), "--json"))


def test_reduce_writes_a_scenario_that_runs_like_the_clis(cli, tmp_path):
    out = tmp_path / "r"
    red = squeal.reduce(FE_BRAKE, out=out, set={"modal.cutoff_hz": 2100})
    assert red["boundary"] == ["6_1", "6_3", "6_5", "9001_1", "9001_3", "9002_1", "9002_3"]
    n = len(red["boundary"]) + len(red["generalised"])
    assert red["M"].shape == (n, n) and np.array_equal(red["M"], red["M"].T)
    assert sorted(p.name for p in out.iterdir()) == ["C.mtx", "K.mtx", "M.mtx", "reduce.json", "scenario.toml"]
    cli("reduce", str(FE_BRAKE), "--set", "modal.cutoff_hz=2100", "--out", str(tmp_path / "c"))
    for f in ("scenario.toml", "M.mtx", "K.mtx", "C.mtx"):
        assert (out / f).read_text() == (tmp_path / "c" / f).read_text(), f
    assert json.loads((out / "reduce.json").read_text()) == json.loads((tmp_path / "c" / "reduce.json").read_text())
    st = squeal.stability(out / "scenario.toml", levers=False)
    assert st.growth_rates.max() > 300
    # An existing folder is never replaced, and nothing is left behind.
    with pytest.raises(squeal.ScenarioError, match="exists"):
        squeal.reduce(FE_BRAKE, out=out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c", "r"]
    with pytest.raises(squeal.ScenarioError, match="only a lumped model"):
        squeal.reduce("disc-pad")


def test_bad_key_raises_scenario_error_naming_it():
    with pytest.raises(squeal.ScenarioError, match="bogus_key") as e:
        squeal.simulate(duration=SHORT, bogus_key=1.0)
    assert isinstance(e.value, ValueError)
    with pytest.raises(squeal.ScenarioError, match="N"):
        squeal.stability(N=-5.0)
    with pytest.raises(squeal.ScenarioError, match="no-such-scenario"):
        squeal.stability("no-such-scenario")
    with pytest.raises(squeal.ScenarioError, match="--x and --y both vary V"):
        squeal.map(x=("V", 1, 2, 3), y=("V", 1, 2, 3))


def test_error_messages_are_the_clis(cli):
    exe = __import__("conftest")._find_cli()
    r = subprocess.run([exe, "stability", "disc-pad", "--set", "bogus_key=1"], capture_output=True, text=True)
    assert r.returncode == 2
    with pytest.raises(squeal.ScenarioError) as e:
        squeal.stability(bogus_key=1)
    assert str(e.value) in r.stderr


def test_dict_scenario_equals_its_toml(tmp_path):
    d = squeal.scenario("disc-pad")
    assert isinstance(d, dict) and d["name"] == "disc-pad"
    path = tmp_path / "mine.toml"
    toml_text = squeal._squeal.scenario_doc("spec", "disc-pad", [])[0]
    path.write_text(toml_text)
    a = squeal.simulate(d, duration=SHORT)
    b = squeal.simulate(path, duration=SHORT)
    c = squeal.simulate("disc-pad", duration=SHORT)
    same_bits(a.data, b.data)
    same_bits(a.data, c.data)
    st_a, st_b = squeal.stability(d, levers=False), squeal.stability(str(path), levers=False)
    same_bits(st_a.eigenvalues.view(np.float64), st_b.eigenvalues.view(np.float64))


def test_scenarios_lists_builtins():
    names = squeal.scenarios()
    assert "disc-pad" in names
    for n in names:
        assert squeal.scenario(n)["name"] == n


def _interrupt_after(delay):
    script = textwrap.dedent(
        """
        import signal, sys, time, squeal
        # A parent started in the background of a non-interactive shell
        # passes SIGINT down ignored, and Python then installs no
        # KeyboardInterrupt handler: restore it, as a terminal would have it.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        print("start", flush=True)
        t0 = time.monotonic()
        try:
            squeal.simulate("disc-pad", duration=140.0, sample_rate=70000.0)
        except KeyboardInterrupt:
            print("interrupted", time.monotonic() - t0, flush=True)
            sys.exit(0)
        print("finished", flush=True)
        sys.exit(1)
        """
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "start"
    time.sleep(delay)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        p.kill()
        raise AssertionError("simulate did not stop within 10 s of SIGINT")
    elapsed = time.monotonic() - sent
    assert p.returncode == 0, out
    assert out.startswith("interrupted"), out
    assert elapsed < 2.0, elapsed


def test_ctrl_c_interrupts_a_long_simulation_promptly():
    _interrupt_after(3.0)


def test_ctrl_c_soon_after_the_start():
    # Early signals too: during the scenario checks and the first second of
    # the run (once seen to be missed under a load of 10 on 2 cores, with an
    # earlier build; not reproduced in 17 tries at delays 0 … 1.5 s since).
    for delay in (0.0, 0.3, 1.0):
        _interrupt_after(delay)


def test_cycle_equals_cli_json(cli):
    doc = json.loads(cli("cycle", "disc-pad", "--json"))
    c = squeal.cycle("disc-pad")
    orbit = c.pop("orbit")
    columns = c.pop("orbit_columns")
    events = c.pop("orbit_events")
    assert c == doc
    # One period of the reversal cycle: the orbit closes on itself (the
    # shooting residual bounds the mismatch) and spans the reported period.
    assert orbit.dtype == np.float64 and orbit.shape == (len(events), len(columns))
    assert columns[0] == "t"
    assert orbit[-1, 0] - orbit[0, 0] == pytest.approx(c["period"], rel=1e-12)
    assert c["multipliers"][0]["abs"] == pytest.approx(1.0, abs=1e-6)


def test_branch_equals_cli_json(cli, tmp_path):
    out = tmp_path / "b"
    doc = json.loads(cli("branch", "belt", "--param", "V=0.2:0.4:3", "--out", str(out), "--json"))
    b = squeal.branch("belt", param=("V", 0.2, 0.4, 3))
    assert b == doc
    # Every grid value is either on the branch or reported as failed.
    grid = [p for p in b["points"] if p["point"] == "grid"]
    assert len(grid) + len(b["failed"]) == 3
    assert all(p["period"] > 0 for p in grid)


def test_cycle_and_branch_bad_input_names_the_flag():
    with pytest.raises(squeal.ScenarioError, match="settle-time"):
        squeal.cycle("disc-pad", settle_time=-1.0)
    with pytest.raises(squeal.ScenarioError, match="bogus"):
        squeal.branch("disc-pad", param=("bogus", 0.5, 0.6, 3))


def test_hb_equals_cli_json_and_the_shooting_cycle(cli):
    doc = json.loads(cli("hb", "hoffmann", "--harmonics", "12", "--json"))
    h = squeal.hb("hoffmann", harmonics=12)
    # Besides the CLI's document, one period of the series as an array.
    orbit, columns = h.pop("orbit"), h.pop("orbit_columns")
    assert h == doc
    assert columns[0] == "t" and sorted(columns[1:]) == sorted(h["amplitude"])
    assert orbit.dtype == np.float64 and orbit.shape == (1025, len(columns))
    assert orbit[0, 0] == 0.0 and orbit[-1, 0] == pytest.approx(h["period"], rel=1e-12)
    # Periodic, and its half peak-to-peak is the document's amplitude (the
    # document samples 4096 points, the array 1024: 1e-3 for these orbits).
    scale = np.abs(orbit[:, 1:]).max(axis=0)
    assert np.all(np.abs(orbit[-1, 1:] - orbit[0, 1:]) <= 1e-9 * scale)
    for j, name in enumerate(columns[1:], start=1):
        half = 0.5 * (orbit[:, j].max() - orbit[:, j].min())
        assert half == pytest.approx(h["amplitude"][name], rel=1e-3)
    c = squeal.cycle("hoffmann")
    assert h["freq_hz"] == pytest.approx(c["frequency_hz"], rel=1e-8)
    assert [r["harmonics"] for r in h["convergence"]] == [3, 6, 12]
    assert len(h["harmonics"]["x"]) == 13
    with pytest.raises(squeal.ScenarioError, match="harmonics 0"):
        squeal.hb("hoffmann", harmonics=0)
    # The thesis law's belt sticks: stick is held as a constraint, and the
    # frequency is shooting's to 1e-3 at H = 20 (measured 1.5e-4).
    b = squeal.hb("belt")
    assert b["stick_constraint"] is True
    assert b["contact_modes"]["belt"]["stick"] > 0.02
    assert b["freq_hz"] == pytest.approx(squeal.cycle("belt")["frequency_hz"], rel=1e-3)


DUFFING = pathlib.Path(__file__).resolve().parents[2] / "scenarios" / "lumped" / "duffing.toml"


def test_hb_forced_response_curve_equals_the_clis(cli, tmp_path):
    # The forced Duffing oscillator's frequency-response curve through both
    # folds: the CLI's document, and the files of out=.
    doc = json.loads(cli("hb", str(DUFFING), "--param", "shaker.freq_hz=10:30:41", "--json"))
    h = squeal.hb(DUFFING, param=("shaker.freq_hz", 10.0, 30.0, 41), out=tmp_path / "frc")
    table, columns = h.pop("table"), h.pop("table_columns")
    assert h == doc
    # The table is branch.csv's numbers, row by row.
    with open(tmp_path / "frc" / "branch.csv") as f:
        rows = list(csv.DictReader(f))
    assert table.dtype == np.float64 and table.shape == (len(rows), len(columns))
    assert columns[:3] == ["shaker.freq_hz", "period", "freq_hz"]
    for r, row in zip(table, rows):
        for c, v in zip(columns, r):
            assert v == pytest.approx(float(row[c]), rel=1e-12), c
    assert h["forced"] is True and len(h["folds"]) == 2
    assert 22.2 < h["folds"][0] < 22.45 and 17.1 < h["folds"][1] < 17.35
    assert json.loads((tmp_path / "frc" / "summary.json").read_text()) == h
    assert (tmp_path / "frc" / "branch.csv").read_text().count(",fold") == 2
    one = squeal.hb(DUFFING)
    assert one["forced"] is True and one["forcing_hz"] == 15.0 and one["stable"] is True
    with pytest.raises(squeal.ScenarioError, match="forced"):
        squeal.cycle(DUFFING)


def test_nma_equals_the_clis(cli, tmp_path):
    damper = DUFFING.parent / "friction-damper.toml"
    doc = json.loads(cli("nma", str(damper), "--modal-amplitude", "1e-4:1:7", "--json"))
    n = squeal.nma(damper, modal_amplitude=(1e-4, 1.0, 7), out=tmp_path / "n")
    table, columns = n.pop("table"), n.pop("table_columns")
    assert n == doc
    with open(tmp_path / "n" / "nma.csv") as f:
        rows = list(csv.DictReader(f))
    assert table.shape == (7, len(columns)) and len(rows) == 7
    for r, row in zip(table, rows):
        for c, v in zip(columns, r):
            assert v == pytest.approx(float(row[c]), rel=1e-12), c
    assert len(n["points"]) == 7 and n["mode"] == 1
    assert (tmp_path / "n" / "nma.csv").read_text().count("\n") == 8
    with pytest.raises(squeal.ScenarioError, match="lumped"):
        squeal.nma("hoffmann", modal_amplitude=(1e-3, 1e-2, 3))


def test_reproduce_equals_the_clis_table_and_conclusions(cli, tmp_path):
    cli("reproduce", "--duration-scale", "0.5", "--no-figures", "--out", str(tmp_path / "r"))
    r = squeal.reproduce(duration_scale=0.5)
    assert r["table_csv"] == (tmp_path / "r" / "table.csv").read_text()
    assert r["conclusions"] == json.loads((tmp_path / "r" / "conclusions.json").read_text())
    assert len(r["sets"]) == 40 and r["sets"][14]["set"] == "15"
    assert [c["id"] for c in r["conclusions"]] == list(range(1, 8))
    with pytest.raises(squeal.ScenarioError, match="duration"):
        squeal.reproduce(duration_scale=-1.0)


def test_listen_writes_the_cli_wav_bytes_and_returns_its_samples(cli, tmp_path):
    # The same scenario through `squeal listen --out a/s.wav` and
    # `squeal.listen(out=b/s.wav)` (the comment chunk names the file): the
    # very same bytes; the samples are the file's (16-bit PCM of the float32
    # samples); the stated RMS level is the samples'.
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    cli("listen", "disc-pad", "--set", "N=2000", "--set", "duration=0.05",
        "--out", str(tmp_path / "a" / "s.wav"))
    r = squeal.listen("disc-pad", out=tmp_path / "b" / "s.wav", N=2000, set={"duration": 0.05})
    written = (tmp_path / "b" / "s.wav").read_bytes()
    assert written == (tmp_path / "a" / "s.wav").read_bytes()
    assert r["wav"] == written
    s = r["samples"]
    assert s.dtype == np.float32 and r["sample_rate"] == 48000
    assert abs(len(s) / 48000 - r["seconds"]) < 1e-12
    start = written.index(b"data") + 8
    pcm = np.frombuffer(written[start:start + 2 * len(s)], dtype="<i2").astype(np.float64)
    assert np.max(np.abs(pcm - np.round(np.clip(s, -1, 1) * 32767.0))) == 0
    rms_db = 10 * np.log10(np.mean(s.astype(np.float64) ** 2))
    assert abs(rms_db - r["rms_dbfs"]) < 1e-3
    assert r["signal"].startswith("v") and r["verdict"]
    # Never over an existing file unless asked; nothing left behind.
    with pytest.raises(squeal.ScenarioError, match="exists"):
        squeal.listen("disc-pad", out=tmp_path / "b" / "s.wav", N=2000, set={"duration": 0.05})
    quieter = squeal.listen("disc-pad", out=tmp_path / "b" / "s.wav", force=True, gain=-6.0,
                            N=2000, set={"duration": 0.05})
    assert abs(quieter["rms_dbfs"] - (r["rms_dbfs"] - 6.0)) < 0.01
    assert [p.name for p in (tmp_path / "b").iterdir()] == ["s.wav"]
    with pytest.raises(squeal.ScenarioError, match="gain"):
        squeal.listen("disc-pad", gain=500.0)
    with pytest.raises(squeal.ScenarioError, match="signal = nope"):
        squeal.listen("disc-pad", signal="nope", set={"duration": 0.01})


def test_cycle_of_the_two_pad_brake_equals_the_clis(cli):
    # Its orbit is reached by a slow growth (σT = 7e-4 a period); settling on
    # after a collapse onto steady sliding used to recurse deep enough to
    # overflow a 2 MB worker thread. The worker has the CLI's 8 MB.
    doc = json.loads(cli("cycle", "two-pad-brake", "--json"))
    c = squeal.cycle("two-pad-brake")
    assert c["period"] == doc["period"] and c["stable"] and doc["stable"]
    assert abs(1.0 / c["period"] - 20751.247) < 0.01
