"""squeal: friction-induced vibration (disc-brake squeal) from Python.

NumPy in, NumPy out, over exactly the engine the ``squeal`` command line
uses (the library crate ``squeal-study``): the same input gives the same bits.

    >>> import squeal
    >>> run = squeal.simulate("disc-pad", duration=0.2, N=2000)
    >>> run["vx_p"], run.summary["verdict"]
    >>> st = squeal.stability("disc-pad", V=2.0)
    >>> st.growth_rates.max(), st.least_stable
    >>> ds = squeal.map("disc-pad", x=("V", 0.5, 20, 40), y=("N", 100, 3000, 30))

``scenario`` is a built-in name (``squeal.scenarios()``), a path to a TOML
file, or a dict with the TOML's structure (``squeal.scenario(name)`` gives
one to edit). Keyword parameters are the CLI's ``--set`` keys (``N=2000``);
``set={"pad1.V": 2.0}`` takes keys that are not Python identifiers.

Every computation releases the GIL and can be interrupted with Ctrl-C
(``KeyboardInterrupt``). Bad input raises :class:`ScenarioError` (a
``ValueError``) with the CLI's one-line message naming the key; numerical
failures raise :class:`SquealError` (a ``RuntimeError``).
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from squeal import _squeal
from squeal._squeal import ScenarioError, SquealError

__all__ = [
    "Run",
    "ScenarioError",
    "SquealError",
    "Stability",
    "branch",
    "critical",
    "cycle",
    "hb",
    "nma",
    "inspect",
    "listen",
    "map",
    "merge",
    "plot",
    "reduce",
    "reproduce",
    "scenario",
    "scenarios",
    "simulate",
    "slurm",
    "stability",
    "sweep",
    "validate",
]

Scenario = Union[str, "os.PathLike[str]", Mapping[str, Any]]
PathLike = Union[str, "os.PathLike[str]"]
Axis = Tuple[str, float, float, int]


def _source(scenario: Scenario) -> Tuple[str, str]:
    """The (kind, text) pair the compiled module resolves a scenario from."""
    if isinstance(scenario, Mapping):
        try:
            return "json", json.dumps(scenario, allow_nan=True, default=_plain)
        except TypeError as e:
            raise ScenarioError(f"scenario dict: {e}") from None
    if isinstance(scenario, (str, os.PathLike)):
        return "spec", os.fspath(scenario)
    raise ScenarioError(
        f"scenario {scenario!r}: expected a built-in name, a path to a TOML file or a dict"
    )


def _plain(v: Any) -> Any:
    """NumPy scalars and arrays inside a scenario dict, as plain Python."""
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise TypeError(f"{v!r} ({type(v).__name__}) has no TOML form")


def _value(v: Any) -> str:
    """A --set value as the command line would spell it (floats round-trip)."""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _sets(set: Optional[Mapping[str, Any]], params: Mapping[str, Any]) -> List[str]:
    """`--set KEY=VALUE` strings from the `set` dict, then the keyword params."""
    out = []
    for d in (set or {}), params:
        for k, v in d.items():
            out.append(f"{k}={_value(v)}")
    return out


def scenarios() -> List[str]:
    """The built-in scenario names (as ``squeal scenario list`` gives them)."""
    return list(_squeal.scenarios())


def scenario(name: Scenario = "disc-pad", *, set: Optional[Mapping[str, Any]] = None, **params: Any) -> Dict[str, Any]:
    """A scenario as a dict with the structure of its TOML file (``squeal
    scenario show``), with overrides applied; edit it and pass it back as the
    ``scenario`` of any function."""
    _, doc = _squeal.scenario_doc(*_source(name), _sets(set, params))
    return dict(json.loads(doc))


class Run:
    """A simulated run.

    ``t`` (float64), ``columns`` (names), ``data`` (samples × columns,
    float64; each column contiguous), ``run["vx_p"]`` (one column, a view),
    ``events`` (dict of arrays ``t``, ``kind``, ``contact``), ``summary`` (the
    dict ``summary.json`` holds: verdict, squeal answer, spectra peaks, …),
    ``spectra`` (``{signal: (freq_hz, psd)}``, the Welch spectra behind the
    summary), ``sample_rate`` (Hz), ``out`` (the run folder written, or None).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.out: Optional[str] = raw.get("out")
        self.columns: List[str] = list(raw["columns"])
        self.data: np.ndarray = raw["data"]
        self.events: Dict[str, np.ndarray] = {
            "t": raw["event_t"],
            "kind": np.array(raw["event_kind"], dtype=str),
            "contact": np.array(raw["event_contact"], dtype=str),
        }
        self.summary: Dict[str, Any] = json.loads(raw["summary"])
        self.spectra: Dict[str, Tuple[np.ndarray, np.ndarray]] = dict(raw["spectra"])
        self.sample_rate: float = raw["sample_rate"]
        self._index = {c: i for i, c in enumerate(self.columns)}

    @property
    def t(self) -> np.ndarray:
        """Sample times (s)."""
        return self.data[:, 0]

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.data[:, self._index[name]]
        except KeyError:
            raise KeyError(f"{name}: no such column; columns are {', '.join(self.columns)}") from None

    def __len__(self) -> int:
        return int(self.data.shape[0])

    def __repr__(self) -> str:
        return (
            f"<squeal.Run {self.summary.get('scenario', {}).get('name', '?')}: "
            f"{self.data.shape[0]} samples × {self.data.shape[1]} columns, "
            f"verdict {self.summary.get('verdict', '?')}>"
        )

    def to_pandas(self) -> Any:
        """The series as a ``pandas.DataFrame`` indexed by ``t`` (needs pandas)."""
        import importlib

        pd: Any = importlib.import_module("pandas")
        return pd.DataFrame(self.data[:, 1:], index=pd.Index(self.t, name="t"), columns=self.columns[1:])

    def to_xarray(self) -> Any:
        """The series as an ``xarray.Dataset`` over ``t`` (needs xarray)."""
        import xarray as xr

        return xr.Dataset(
            {c: ("t", self.data[:, i]) for i, c in enumerate(self.columns) if i > 0},
            coords={"t": self.t},
            attrs={"scenario": self.summary.get("scenario", {}).get("name", ""), "verdict": self.summary.get("verdict", "")},
        )


def simulate(
    scenario: Scenario = "disc-pad",
    *,
    duration: Optional[float] = None,
    out: Optional[PathLike] = None,
    formats: Sequence[str] = ("csv",),
    plots: bool = True,
    wav: bool = False,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Run:
    """Integrate a scenario (``squeal simulate``): a :class:`Run`.
    ``duration`` (s) overrides the scenario's. With ``out``, the CLI's run
    folder is written there too (``summary.json`` — then the run's
    ``summary`` is that file's document —, ``events.csv``, ``spectrum.csv``,
    the series in ``formats`` (``"csv"``, ``"npy"``), the pictures unless
    ``plots=False`` and with ``wav`` ``squeal.wav``); :func:`plot` redraws
    it, :func:`listen` renders its sound."""
    return Run(
        _squeal.simulate(
            *_source(scenario), _sets(set, params), duration, _out(out),
            [str(f) for f in formats], bool(plots), bool(wav),
        )
    )


def plot(
    run_dir: PathLike,
    *,
    window: str = "hann",
    segment: int = 16384,
    overlap: float = 0.5,
    amplitude: bool = False,
    signals: Sequence[str] = (),
    fmax: Optional[float] = None,
    frange: Optional[Tuple[float, float]] = None,
    log_f: bool = False,
) -> List[str]:
    """Redraw the pictures of a saved run folder (``squeal plot RUN_DIR``)
    without simulating again: ``window`` (``"hann"``, ``"flattop"``,
    ``"rect"``), ``segment`` (samples per Welch segment), ``overlap``
    (0 to 0.95), ``amplitude`` (peak amplitude instead of the PSD),
    ``signals`` (velocities to analyse; none: all), ``fmax`` or ``frange``
    (Hz: the band shown), ``log_f`` (logarithmic frequency axes). Only files
    squeal wrote are replaced; ``spectrum.csv`` and ``summary.json`` say what
    the new pictures show. Returns the notes the CLI prints on stderr."""
    fr = None if frange is None else f"{float(frange[0])!r}:{float(frange[1])!r}"
    return list(
        _squeal.plot(
            os.fspath(run_dir), window, int(segment), float(overlap), bool(amplitude),
            [str(x) for x in signals], fmax, fr, bool(log_f),
        )
    )


class Stability:
    """Eigen-analysis of steady sliding (``squeal stability``).

    ``eigenvalues`` (complex128, all 2n, by growth rate descending),
    ``growth_rates`` (Re λ, 1/s), ``frequencies_hz`` (|Im λ|/2π),
    ``damping_ratios`` (−σ/|λ|), ``modes`` (complex mode shapes, 2n × n:
    position part of each eigenvector over its largest component),
    ``dominant`` (dof of each mode), ``dofs``, ``stable``, ``neutral``,
    ``least_stable`` (dict of the least stable mode), ``levers`` (list of
    dicts ``param, from, to, freq_hz``: one-parameter changes that flip the
    verdict), ``to_dict()`` (the document of ``squeal stability --json``).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.eigenvalues: np.ndarray = raw["eigenvalues"]
        self.frequencies_hz: np.ndarray = raw["frequencies_hz"]
        self.damping_ratios: np.ndarray = raw["damping_ratios"]
        self.modes: np.ndarray = raw["modes"]
        self.dominant: List[str] = list(raw["dominant"])
        self.dofs: List[str] = list(raw["dofs"])
        self.stable: bool = raw["stable"]
        self.neutral: bool = raw["neutral"]
        self.out: Optional[str] = raw.get("out")
        self._text: str = raw["document"]
        self._doc: Optional[Dict[str, Any]] = None
        k = raw["least_stable"]
        lam = self.eigenvalues[k]
        self.least_stable: Dict[str, Any] = {
            "re": float(lam.real), "im": float(lam.imag),
            "freq_hz": float(self.frequencies_hz[k]), "dominant": self.dominant[k],
        }

    def _document(self) -> Dict[str, Any]:
        if self._doc is None:
            self._doc = json.loads(self._text)
        return self._doc

    @property
    def levers(self) -> List[Dict[str, Any]]:
        """One-parameter changes that flip the verdict: ``param, from, to, freq_hz``."""
        return list(self._document()["levers"])

    @property
    def growth_rates(self) -> np.ndarray:
        """Re λ of every eigenvalue (1/s)."""
        return self.eigenvalues.real.copy()

    def to_dict(self) -> Dict[str, Any]:
        """The document ``squeal stability --json`` prints."""
        return dict(json.loads(self._text))

    def __repr__(self) -> str:
        verdict = "stable" if self.stable else "neutral" if self.neutral else "unstable"
        return f"<squeal.Stability {verdict}: max growth rate {self.eigenvalues[0].real:+.6e} 1/s>"


def stability(
    scenario: Scenario = "disc-pad",
    *,
    levers: bool = True,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Stability:
    """Stability of steady sliding (``squeal stability``): a :class:`Stability`.
    ``levers=False`` skips the search for verdict-flipping parameter changes
    (hundreds of analyses). With ``out``, ``modes.csv`` (every mode's
    eigenvalue and shape, as ``squeal stability --out``) is written there."""
    return Stability(_squeal.stability(*_source(scenario), _sets(set, params), levers, _out(out)))


def _axis(a: Sequence[Any], what: str) -> Axis:
    try:
        name, lo, hi, n = a
        return (str(name), float(lo), float(hi), int(n))
    except (TypeError, ValueError):
        raise ScenarioError(f"{what} {a!r}: expected (NAME, LO, HI, N)") from None


def map(
    scenario: Scenario = "disc-pad",
    *,
    x: Axis = ("V", 0.5, 20.0, 40),
    y: Axis = ("N", 100.0, 3000.0, 30),
    transient: bool = False,
    log_x: bool = False,
    log_y: bool = False,
    duration: Optional[float] = None,
    threads: Optional[int] = None,
    shard: Optional[Tuple[int, int]] = None,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Any:
    """Stability over a grid of two parameters (``squeal map``), in parallel
    and deterministic (any ``threads``: the same bits).

    ``x`` and ``y`` are ``(NAME, LO, HI, N)`` (``LO``, ``HI`` in the
    parameter's units), spaced logarithmically with ``log_x``/``log_y``;
    ``duration`` (s) is the simulated time per point with ``transient``.

    An ``xarray.Dataset`` with coordinates named after the parameters and
    variables ``max_growth_rate`` (1/s, NaN where steady sliding does not
    exist) and ``freq_hz`` (Hz), plus ``outcome``, ``rms_tangential`` (m/s),
    ``stick_fraction`` (1), ``t_end`` (s), ``agree`` and ``spl_dba`` (dB(A) re
    20 µPa at the scenario's ``radiation.distance_m``, NaN without radiating
    surfaces) with ``transient=True``; every variable and coordinate has
    ``units`` and ``long_name``. Without xarray a dict of the same names
    (2-D arrays, y × x, and the two coordinate arrays).

    ``out``: also write the CLI's files there (``map.csv``, ``map.png``, …;
    the folder is written beside and swapped in, never over a folder squeal
    did not write). ``shard=(k, n)``: compute only the points whose flat
    index ``i`` has ``i mod n = k`` and write them as the CLI's shard
    (``shard.json`` + ``part.csv``, into ``out`` or ``out/NAME-map-shard-K-of-N``)
    for :func:`merge`; then the result is the dict ``squeal map --shard
    --json`` prints: ``shard``, ``shards``, ``points``, ``grid_points``,
    ``out``."""
    raw = _squeal.stability_map(
        *_source(scenario), _sets(set, params), _axis(x, "x"), _axis(y, "y"),
        log_x, log_y, transient, duration, threads, _shard(shard), _out(out),
    )
    if shard is not None:
        return dict(raw)
    return _map_result(raw)


_MAP_META = {
    "max_growth_rate": ("1/s", "maximum growth rate σ of steady sliding's eigenvalues"),
    "freq_hz": ("Hz", "frequency of the maximum-growth eigenvalue"),
    "outcome": ("1", "outcome of the simulated run"),
    "rms_tangential": ("m/s", "RMS tangential velocity over the judged window"),
    "stick_fraction": ("1", "fraction of the time a contact sticks"),
    "t_end": ("s", "time the simulated run ended"),
    "agree": ("1", "whether the linear verdict and the simulated outcome agree"),
    "spl_dba": ("dB(A) re 20 µPa", "A-weighted sound pressure level of the last window"),
}


def _map_result(raw: Mapping[str, Any]) -> Any:
    """A map's Dataset (or dict) from the compiled module's flat arrays."""
    xn, yn = raw["x_name"], raw["y_name"]
    shape = (len(raw["y"]), len(raw["x"]))
    grids = {k: np.asarray(raw[k]).reshape(shape) for k in _MAP_META if k in raw}
    try:
        import xarray as xr
    except ImportError:
        return {xn: raw["x"], yn: raw["y"], **grids}
    ds = xr.Dataset(
        {k: ((yn, xn), v) for k, v in grids.items()},
        coords={xn: raw["x"], yn: raw["y"]},
    )
    ds[xn].attrs.update(units=raw["x_unit"], long_name=f"parameter {xn}")
    ds[yn].attrs.update(units=raw["y_unit"], long_name=f"parameter {yn}")
    for k in grids:
        units, long_name = _MAP_META[k]
        ds[k].attrs.update(units=units, long_name=long_name)
    if raw.get("out") is not None:
        ds.attrs["out"] = raw["out"]
    return ds


def critical(
    scenario: Scenario = "disc-pad",
    *,
    param: Tuple[str, float, float] = ("V", 1.0, 16.5),
    grid: int = 64,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """Where steady sliding changes stability (``squeal critical``):
    ``{"param", "value", "freq_hz"}`` (plus ``direction`` and
    ``from_neutral`` when found; ``value`` and ``freq_hz`` None when nothing
    crosses in the interval; ``modal``: how the eigenvalues are computed) —
    the document of ``squeal critical --json``."""
    try:
        name, lo, hi = param
        lo, hi = float(lo), float(hi)
    except (TypeError, ValueError):
        raise ScenarioError(f"param {param!r}: expected (NAME, LO, HI)") from None
    return dict(json.loads(_squeal.critical(*_source(scenario), _sets(set, params), str(name), lo, hi, int(grid))))


def sweep(
    scenario: Scenario = "disc-pad",
    *,
    param: Axis,
    shard: Optional[Tuple[int, int]] = None,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Any:
    """Eigenvalues tracked along one parameter (``squeal sweep``).

    ``param`` is ``(NAME, LO, HI, N)`` as ``--param``. With xarray
    installed, an ``xarray.Dataset`` over the dimensions ``NAME`` (the
    parameter values, with their ``units``) and ``branch`` (eigenvalues
    followed by mode matching, the CLI's branches): ``eigenvalue``
    (complex128, 1/s), ``growth_rate`` (Re λ, 1/s), ``freq_hz`` (|Im λ|/2π,
    Hz), ``listed`` (bool per branch: the ones the CLI lists, one per mode),
    and the attributes ``onset_value``, ``onset_freq_hz`` (Hz),
    ``onset_direction`` (``destabilising``/``stabilising``) and
    ``onset_coalescence`` (1 where two modes coalesce, 0 for a lone
    crossing) — one entry per change of the number of growing eigenvalues.
    Every variable and coordinate has ``units`` and ``long_name``.
    Without xarray, a dict: ``param``, ``values``, ``eigenvalues`` (values ×
    branches), ``growth_rates``, ``frequencies_hz``, ``listed`` (indices),
    ``onsets`` (list of dicts).

    ``out``: also write the CLI's files there (``sweep.csv``,
    ``sweep.png``/``.svg``). ``shard=(k, n)``: compute only the k-th of n
    contiguous slices of the values (and the two values before it, to track
    the modes across the boundary) and write it as the CLI's shard for
    :func:`merge`; the result is then ``squeal sweep --shard --json``'s dict
    (``shard``, ``shards``, ``values``, ``first``, ``computed_from``, ``out``).
    """
    raw = _squeal.sweep(
        *_source(scenario), _sets(set, params), _axis(param, "param"), _shard(shard), _out(out)
    )
    if shard is not None:
        return dict(raw)
    return _sweep_result(raw)


def _sweep_result(raw: Mapping[str, Any]) -> Any:
    """A sweep's Dataset (or dict) from the compiled module's arrays."""
    lam = raw["eigenvalues"]
    onsets = json.loads(raw["onsets"])
    try:
        import xarray as xr
    except ImportError:
        return {
            "param": raw["param"],
            "values": raw["values"],
            "eigenvalues": lam,
            "growth_rates": lam.real.copy(),
            "frequencies_hz": np.abs(lam.imag) / (2 * np.pi),
            "listed": list(raw["listed"]),
            "onsets": onsets,
            "out": raw.get("out"),
        }
    name = raw["param"]
    nb = lam.shape[1]
    listed = np.zeros(nb, dtype=bool)
    listed[list(raw["listed"])] = True
    ds = xr.Dataset(
        {
            "eigenvalue": ((name, "branch"), lam),
            "growth_rate": ((name, "branch"), lam.real.copy()),
            "freq_hz": ((name, "branch"), np.abs(lam.imag) / (2 * np.pi)),
            "listed": (("branch",), listed),
        },
        coords={name: raw["values"], "branch": np.arange(nb)},
        attrs={
            "onset_value": [float(o["value"]) for o in onsets],
            "onset_freq_hz": [float(o["freq_hz"]) for o in onsets],
            "onset_direction": [str(o["direction"]) for o in onsets],
            "onset_coalescence": [int(bool(o["coalescence"])) for o in onsets],
        },
    )
    meta = {
        name: (raw["unit"], f"parameter {name}"),
        "branch": ("1", "eigenvalue branch (followed by mode matching)"),
        "eigenvalue": ("1/s", "eigenvalue λ = σ + iω of the linearised steady sliding"),
        "growth_rate": ("1/s", "growth rate σ = Re λ"),
        "freq_hz": ("Hz", "frequency |Im λ|/2π"),
        "listed": ("1", "branch listed by the CLI (one per mode)"),
    }
    for k, (units, long_name) in meta.items():
        ds[k].attrs.update(units=units, long_name=long_name)
    if raw.get("out") is not None:
        ds.attrs["out"] = raw["out"]
    return ds


def reproduce(
    *,
    duration_scale: float = 1.0,
    figures: bool = True,
    shard: Optional[Tuple[int, int]] = None,
    out: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """The thesis reproduced (``squeal reproduce``): the 40 reconstructed
    sets run and measured in parallel, the sweeps around set 15 and the
    seven conclusions graded.

    ``table_csv`` (the text of ``table.csv``), ``sets`` (its rows as dicts of
    strings, keyed by its header: ``set``, ``V`` (m/s), ``N`` (N), …,
    ``max_growth_rate`` (1/s), ``squeal_frequency_hz`` (Hz), ``erp_db``,
    ``spl_dba``), ``conclusions`` (``conclusions.json``: ``id``, ``thesis``,
    ``claim``, ``held``, ``grade``, ``caveat``, ``evidence``, ``data``) and
    ``out`` (where the files went, or None). ``duration_scale`` scales every
    set's duration (the CLI's ``--duration-scale``).

    ``out``: also write the report there (``report.html``, ``report.md``,
    ``table.csv``, ``conclusions.json``, the V × N map and, with
    ``figures``, each set's Appendix A pictures). ``shard=(k, n)``: measure
    only the sets whose index ``i`` (set ``i + 1``) has ``i mod n = k`` and
    write them as the CLI's shard for :func:`merge` (into ``out`` or
    ``out/reproduce-shard-K-of-N``); ``sets`` then holds those sets only and
    ``conclusions`` is empty (they need all 40)."""
    table, conclusions, dest = _squeal.reproduce(
        float(duration_scale), bool(figures), _shard(shard), _out(out)
    )
    return _reproduce_result(table, conclusions, dest)


def _reproduce_result(table: str, conclusions: str, dest: Optional[str]) -> Dict[str, Any]:
    import csv
    import io

    return {
        "table_csv": table,
        "sets": list(csv.DictReader(io.StringIO(table))),
        "conclusions": json.loads(conclusions),
        "out": dest,
    }


def merge(paths: Sequence[PathLike], *, out: PathLike) -> Any:
    """Gather the shards of one study (``squeal merge DIR… --out DIR``):
    every shard folder of a map, a sweep or ``reproduce``, in any order,
    checked to belong together and to be complete (:class:`ScenarioError`
    names a missing shard's points, a shard given twice, a changed file),
    written into ``out`` as the unsharded study's files, byte for byte.
    Returns what the unsharded study returns: :func:`map`'s Dataset,
    :func:`sweep`'s Dataset or :func:`reproduce`'s dict."""
    kind, raw = _squeal.merge([os.fspath(p) for p in paths], os.fspath(out))
    if kind == "map":
        return _map_result(raw)
    if kind == "sweep":
        return _sweep_result(raw)
    return _reproduce_result(raw["table"], raw["conclusions"], raw["out"])


def slurm(
    study: str,
    scenario: Scenario = "disc-pad",
    *,
    tasks: int,
    x: Optional[Axis] = None,
    y: Optional[Axis] = None,
    log_x: bool = False,
    log_y: bool = False,
    transient: bool = False,
    duration: Optional[float] = None,
    param: Optional[Axis] = None,
    duration_scale: float = 1.0,
    figures: bool = True,
    out: Optional[PathLike] = None,
    jobs: Optional[PathLike] = None,
    partition: Optional[str] = None,
    time: Optional[str] = None,
    cpus_per_task: Optional[int] = None,
    submit: bool = False,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """A study as a SLURM job array (``squeal slurm map|sweep|reproduce``):
    ``study`` is ``"map"`` (with ``x``, ``y`` and :func:`map`'s options),
    ``"sweep"`` (with ``param``) or ``"reproduce"`` (``duration_scale``,
    ``figures``); ``tasks`` shards, each an array task running this Python's
    squeal (``python -m squeal STUDY … --shard K/N``), and a merge job after
    them that writes the whole study into ``out`` (default the CLI's
    ``out/NAME-map``, ``out/NAME-sweep`` or ``out/reproduce``).

    The scripts ``array.sh`` and ``merge.sh`` go into ``jobs`` (default
    ``OUT-slurm``) with the scenario when it is a dict (``scenario.json``);
    ``partition``, ``time`` (SLURM's format, e.g. ``"2:00:00"``) and
    ``cpus_per_task`` become ``#SBATCH`` lines (squeal's threads follow
    ``SLURM_CPUS_PER_TASK``). With ``submit``, ``sbatch`` submits both.
    Returns ``jobs``, ``array``, ``merge``, ``out``, ``submit_line`` (the
    command that submits them by hand), ``rerun_line`` and, when submitted,
    ``array_job`` and ``merge_job`` (SLURM's job ids)."""
    import sys

    kind, text = _source(scenario)
    sets = _sets(set, params)
    extra: List[Tuple[str, str]] = []
    if kind == "json":
        extra.append(("scenario.json", text + "\n"))
    args = [study]
    if study in ("map", "sweep"):
        if kind == "json":
            # The tasks read the dict back from the jobs folder.
            args.append("@scenario.json")
        else:
            args.append(os.path.abspath(text) if os.path.exists(text) else text)
        for s_ in sets:
            args += ["--set", s_]
    if study == "map":
        if x is None or y is None:
            raise ScenarioError("slurm map: needs x and y, as (NAME, LO, HI, N)")
        args += ["--x", _axis_text(_axis(x, "x")), "--y", _axis_text(_axis(y, "y"))]
        args += ["--log-x"] * bool(log_x) + ["--log-y"] * bool(log_y)
        args += ["--transient"] * bool(transient)
        if duration is not None:
            args += ["--duration", repr(float(duration))]
    elif study == "sweep":
        if param is None:
            raise ScenarioError("slurm sweep: needs param, as (NAME, LO, HI, N)")
        args += ["--param", _axis_text(_axis(param, "param"))]
    elif study == "reproduce":
        args += ["--duration-scale", repr(float(duration_scale))]
        args += ["--no-figures"] * (not figures)
    return dict(
        _squeal.slurm(
            study, kind, text, sets, [sys.executable, "-m", "squeal"], args, int(tasks),
            _axis(x, "x") if x is not None else None,
            _axis(y, "y") if y is not None else None,
            bool(log_x), bool(log_y), bool(transient), duration,
            _axis(param, "param") if param is not None else None,
            float(duration_scale), _out(out), partition, time, cpus_per_task,
            _out(jobs), bool(submit), extra,
        )
    )


def _axis_text(a: Axis) -> str:
    """``(NAME, LO, HI, N)`` as the CLI's ``NAME=LO:HI:N`` (floats round-trip)."""
    return f"{a[0]}={a[1]!r}:{a[2]!r}:{a[3]}"


def _shard(shard: Optional[Sequence[int]]) -> Optional[Tuple[int, int]]:
    if shard is None:
        return None
    try:
        k, n = shard
        return (int(k), int(n))
    except (TypeError, ValueError):
        raise ScenarioError(f"shard {shard!r}: expected (K, N), K counting from 0") from None


def _out(out: Optional[PathLike]) -> Optional[str]:
    return None if out is None else os.fspath(out)


def validate(filter: Optional[str] = None) -> Dict[str, Any]:
    """squeal's benchmark cases (``squeal validate --json``): ``{"cases":
    [{"name", "kind", "quantity", "unit", "reference", "source", "value",
    "error", "error_kind", "tolerance", "pass", "detail"}], "passed",
    "failed"}``; ``filter`` keeps the cases whose name contains it."""
    return dict(json.loads(_squeal.validate(filter)))


def inspect(scenario: Scenario = "disc-pad", *, set: Optional[Mapping[str, Any]] = None, **params: Any) -> Dict[str, Any]:
    """What a scenario's files hold (``squeal inspect --json``): each
    matrix's format, file, size, nonzeros and symmetry, the dofs, the lowest
    natural frequencies without friction (Hz), each contact with its dofs."""
    return dict(json.loads(_squeal.inspect(*_source(scenario), _sets(set, params))))


def reduce(
    scenario: Scenario,
    *,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """A lumped (FE) model reduced by Craig–Bampton (``squeal reduce``):
    every dof the scenario names kept physical, the interior's
    fixed-interface modes up to ``modal.cutoff_hz`` (Hz; or the
    ``modal.modes`` lowest).

    The record (``reduce.json``: ``boundary``, ``generalised``,
    ``modes_hz`` (Hz), ``interior_modes``, ``dofs``, ``basis``,
    ``shifted``), plus ``toml`` (the reduced scenario) and ``M`` (kg), ``K``
    (N/m), ``C`` (N·s/m; absent without a damping file) as dense arrays on
    ``boundary + generalised``. With ``out``, also writes that folder
    (``scenario.toml``, ``M.mtx``, ``K.mtx``, ``C.mtx``, ``reduce.json``) —
    a new folder only: an existing ``out`` is refused, never replaced —
    and ``squeal.simulate(out + "/scenario.toml")`` runs it.
    """
    raw = _squeal.reduce(*_source(scenario), _sets(set, params))
    doc: Dict[str, Any] = json.loads(raw["document"])
    files = {"scenario.toml": raw["toml"], "reduce.json": json.dumps(doc, indent=2) + "\n"}
    for k in ("M", "K", "C"):
        if k in raw:
            doc[k] = raw[k]
            files[f"{k}.mtx"] = raw[f"{k}.mtx"]
    doc["toml"] = raw["toml"]
    if out is not None:
        _write_new_folder(os.fspath(out), files)
    return doc


def listen(
    scenario: Scenario = "disc-pad",
    *,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    signal: Optional[str] = None,
    gain: float = 0.0,
    transpose: float = 0.0,
    float32: bool = False,
    force: bool = False,
    duration: Optional[float] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """A run as sound (``squeal listen``): the scenario simulated and one
    velocity rendered at true pitch, 48 kHz, at a fixed level reference —
    full scale is ``full_scale_m_per_s`` (2 m/s) at ``gain`` 0 dB, no
    normalisation, so a brake that vibrates ten times as fast sounds 20 dB
    louder.

    ``signal``: the velocity column to hear (default: the one that
    squeals, else the one with the most energy); ``gain`` in dB (within
    ±200); ``transpose`` in octaves (within ±6; a listening aid, not the
    true pitch). Returns a dict: ``samples`` (float32 array in [-1, 1]),
    ``sample_rate`` (Hz), ``seconds`` (s), ``signal``, ``rms_dbfs`` (dB re
    full scale), ``clipped_samples``, ``looped`` (the run was shorter than
    the clip and its last fifth was looped), ``source_seconds`` (s),
    ``verdict``, ``squeal_hz`` (Hz or None), ``level`` and ``note`` (the
    lines ``squeal listen`` prints), and ``wav`` (the file's bytes: 16-bit
    PCM, or 32-bit float with ``float32``). With ``out``, the WAV is also
    written there — the very bytes ``squeal listen --out`` writes — never
    over an existing file unless ``force``; it is written beside ``out``
    and renamed into place, so an interrupted call leaves nothing.
    ``IPython.display.Audio(r["samples"], rate=r["sample_rate"],
    normalize=False)`` plays it in a notebook.
    """
    name = os.path.basename(os.fspath(out)) if out is not None else "squeal.wav"
    if out is not None:
        path = os.fspath(out)
        if os.path.lexists(path) and not force:
            raise ScenarioError(f"out = {path!r}: exists; pass force=True to replace it")
        parent = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(parent):
            raise ScenarioError(f"out = {path!r}: its folder {parent!r} does not exist")
    raw = _squeal.listen(
        *_source(scenario), _sets(set, params), duration, signal,
        float(gain), float(transpose), bool(float32), name,
    )
    if out is not None:
        _write_file(os.fspath(out), raw["wav"], force)
    return raw


def _write_file(path: str, data: bytes, force: bool) -> None:
    """Write ``data`` to ``path``: staged beside it and renamed into place
    (an interrupted call leaves nothing); an existing file is replaced only
    with ``force`` (without it, a file that appeared meanwhile is kept)."""
    import tempfile

    parent = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".squeal-", suffix=".wav", dir=parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        if force:
            os.replace(tmp, path)
        else:
            os.link(tmp, path)
            os.unlink(tmp)
    except FileExistsError:
        os.unlink(tmp)
        raise ScenarioError(f"out = {path!r}: exists; pass force=True to replace it") from None
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise


def _write_new_folder(out: str, files: Mapping[str, str]) -> None:
    """Write ``files`` into the new folder ``out``: staged beside it and
    renamed into place, so that an interrupted call leaves nothing."""
    import shutil
    import tempfile

    if os.path.lexists(out):
        raise ScenarioError(f"out = {out!r}: exists; reduce writes a new folder and never replaces one")
    parent = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(parent):
        raise ScenarioError(f"out = {out!r}: its folder {parent!r} does not exist")
    tmp = tempfile.mkdtemp(prefix=".squeal-reduce-", dir=parent)
    try:
        for name, text in files.items():
            with open(os.path.join(tmp, name), "w", encoding="utf-8") as f:
                f.write(text)
        os.rename(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _orbit_document(raw: Dict[str, Any]) -> Dict[str, Any]:
    """A binding's answer with an orbit: its JSON document, ``out`` (where
    the files went, if anywhere) and ``orbit`` with ``orbit_columns``."""
    doc: Dict[str, Any] = json.loads(raw["document"])
    if raw["out"] is not None:
        doc["out"] = raw["out"]
    if "orbit" in raw:
        doc["orbit_columns"] = list(raw["orbit_columns"])
        doc["orbit"] = raw["orbit"]
    return doc


def cycle(
    scenario: Scenario = "disc-pad",
    *,
    section: Optional[str] = None,
    settle_steps: int = 20_000_000,
    settle_time: float = 1000.0,
    settle_tol: float = 1e-2,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """The limit cycle the scenario settles on (``squeal cycle --json``):
    the CLI's document (``period``, ``multipliers`` as ``{re, im, abs}``,
    ``stable``, ``amplitude``, ``events_per_period``, the shooting residual,
    …) plus ``orbit`` (one period, rows × ``orbit_columns``, float64) and
    ``orbit_events`` (the event kind on each row, "" for none).
    ``section`` is ``"STATE"`` or ``"STATE=LEVEL"`` as ``--section``;
    ``settle_time`` is in s. With ``out``, the CLI's files (``orbit.csv``,
    ``summary.json``, the pictures) are written there and ``out`` says where.
    """
    raw = _squeal.cycle(
        *_source(scenario),
        _sets(set, params),
        int(settle_steps),
        float(settle_time),
        float(settle_tol),
        section,
        _out(out),
    )
    doc = _orbit_document(raw)
    if "orbit_events" in raw:
        doc["orbit_events"] = list(raw["orbit_events"])
    return doc


def hb(
    scenario: Scenario = "disc-pad",
    *,
    harmonics: int = 20,
    guess: str = "settle",
    settle_steps: int = 20_000_000,
    settle_time: float = 1000.0,
    settle_tol: float = 1e-2,
    param: Optional[Axis] = None,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """The periodic orbit by harmonic balance (``squeal hb --json``): of a
    forced model (a ``[[force]]`` with ``amplitude`` and ``freq_hz``) its
    periodic response at the forcing frequency (``forced``, ``forcing_hz``),
    else the self-excited orbit. ``freq_hz`` (Hz) and ``period`` (s); ``amplitude`` per state
    (half peak-to-peak, m or m/s); ``harmonics`` per dof (the mean, then
    the amplitude of harmonics 1…H, m); ``contact_modes`` (fraction of the
    period each contact spends in slip+, slip−, stick, free);
    ``stick_constraint`` (true where the orbit sticks and stick was held as a
    constraint by the dynamic Lagrangian step);
    ``multipliers`` as ``{re, im, abs, trivial}`` and ``stable`` from one
    exact period from the HB orbit, whose scaled miss is
    ``shooting_defect``; ``hill`` (of a smooth orbit, without mode
    switches: ``multipliers`` and ``max_multiplier`` by Hill's method from
    the series alone; ``None`` otherwise); ``convergence`` (rows for H/4, H/2, H:
    ``harmonics``, ``freq_hz``, ``amplitude_change``, ``residual``);
    ``warnings``; ``guess`` (where the first guess came from). ``harmonics``
    is H (1…400); ``guess`` is ``"settle"`` (a settled simulation, as
    ``cycle``) or ``"hopf"`` (steady sliding's growing mode, no simulation,
    settling only if that finds no stable orbit); the settling options are
    ``cycle``'s. Orbits that stick are solved with stick as a constraint.
    With ``out``, the CLI's files (``hb_orbit.csv``, ``summary.json``, ``hb.png``) are
    written there.

    With ``param=(NAME, LO, HI, N)`` (``--param``) the solution is followed
    from ``NAME = LO`` to ``HI`` by pseudo-arclength continuation through
    folds, steps of at most ``(HI − LO)/(N − 1)``: a forced model's
    frequency-response curve with ``"<force>.freq_hz"``. The document then
    has ``points`` (per point ``value``, ``freq_hz``, ``period``,
    ``amplitude`` per state, ``max_multiplier``, ``stable``, ``point``:
    ``step`` or ``fold``), ``folds`` (the parameter at each), ``end``,
    ``start`` (the document at ``LO``; None when there is no orbit there and
    the branch starts at ``critical``'s Hopf point in the range, which
    ``hopf`` then gives as ``value`` and ``freq_hz``) and ``warnings``, and ``table``
    (float64, one row per point, as ``branch.csv`` without ``stable`` and
    ``point``) with its ``table_columns``; ``out`` gets ``branch.csv``,
    ``summary.json`` and ``hb_branch.png``.

    Without ``param``, besides the document: ``orbit`` (float64, one
    period of the series sampled, rows × ``orbit_columns``: ``t`` and the
    states), as ``cycle`` returns its orbit."""
    if param is not None:
        branch_doc: Dict[str, Any] = dict(
            json.loads(
                _squeal.hb_branch(
                    *_source(scenario),
                    _sets(set, params),
                    _axis(param, "param"),
                    int(harmonics),
                    int(settle_steps),
                    float(settle_time),
                    float(settle_tol),
                    _out(out),
                )
            )
        )
        points = branch_doc["points"]
        names = list(points[0]["amplitude"]) if points else []
        columns = [str(param[0]), "period", "freq_hz"] + [f"amplitude_{n}" for n in names]
        columns += ["max_multiplier"]
        branch_doc["table_columns"] = columns
        branch_doc["table"] = np.array(
            [
                [p["value"], p["period"], p["freq_hz"]]
                + [p["amplitude"][n] for n in names]
                + [np.nan if p["max_multiplier"] is None else p["max_multiplier"]]
                for p in points
            ],
            dtype=np.float64,
        ).reshape(-1, len(columns))
        return branch_doc
    raw = _squeal.hb(
        *_source(scenario),
        _sets(set, params),
        int(harmonics),
        int(settle_steps),
        float(settle_time),
        float(settle_tol),
        str(guess),
        _out(out),
    )
    return _orbit_document(raw)


def nma(
    scenario: Scenario,
    *,
    modal_amplitude: Tuple[float, float, int],
    mode: int = 1,
    harmonics: int = 20,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """A friction-damped nonlinear mode by the extended periodic motion
    concept (``squeal nma --json``): ``mode`` (numbered from 1 by frequency
    of the model linearised with its contacts stuck, ``linear_hz`` its
    frequency in Hz), and per log-spaced mass-normalised modal amplitude
    (``modal_amplitude=(LO, HI, N)``, m·√kg) the ``points``:
    ``freq_hz`` (Hz), ``damping_ratio``, ``xi`` (the artificial damping,
    1/s), ``amplitude`` per state, ``residual``, ``sticks``,
    ``stick_constraint`` (true where the orbit sticks and stick was held as
    a constraint); ``failures``
    and ``warnings``. Lumped and matrix models only (the mass matrix). With
    ``out``, the CLI's files (``nma.csv``, ``summary.json``, ``nma.png``).
    Besides the document, ``table`` (float64, one row per point, as
    ``nma.csv`` without ``sticks`` and ``stick_constraint``) with its
    ``table_columns``."""
    lo, hi, n = modal_amplitude
    doc: Dict[str, Any] = dict(
        json.loads(
            _squeal.nma(
                *_source(scenario),
                _sets(set, params),
                int(mode),
                (float(lo), float(hi), int(n)),
                int(harmonics),
                _out(out),
            )
        )
    )
    points = doc["points"]
    names = list(points[0]["amplitude"]) if points else []
    columns = ["modal_amplitude", "freq_hz", "xi", "damping_ratio"]
    columns += [f"amplitude_{s}" for s in names] + ["residual"]
    doc["table_columns"] = columns
    doc["table"] = np.array(
        [
            [p["modal_amplitude"], p["freq_hz"], p["xi"], p["damping_ratio"]]
            + [p["amplitude"][s] for s in names]
            + [p["residual"]]
            for p in points
        ],
        dtype=np.float64,
    ).reshape(-1, len(columns))
    return doc


def branch(
    scenario: Scenario = "disc-pad",
    *,
    param: Axis,
    out: Optional[PathLike] = None,
    set: Optional[Mapping[str, Any]] = None,
    **params: Any,
) -> Dict[str, Any]:
    """Continuation of the limit cycle over one parameter
    (``squeal branch --json``): the CLI's document (``points`` with period,
    amplitudes, multipliers and stability; ``bifurcations``; ``segments``;
    ``hopf``). ``param`` is ``(NAME, LO, HI, N)`` as ``--param``. With
    ``out``, the CLI's files (``branch.csv``, ``summary.json``, the
    bifurcation diagram ``branch.png``) are written there."""
    return dict(
        json.loads(
            _squeal.branch(*_source(scenario), _sets(set, params), _axis(param, "param"), _out(out))
        )
    )
