"""Type stubs of the compiled module ``squeal._squeal`` (python/src/lib.rs).

Internal: use the functions of :mod:`squeal`, which convert these raw
results into arrays, dicts and Datasets. Every ``kind, text`` pair is a
scenario source: ``("spec", built-in name or path)`` or ``("json", a
scenario dict as JSON text)``; ``sets`` are ``KEY=VALUE`` strings (the
CLI's ``--set``).
"""

from typing import Any, Dict, List, Optional, Tuple

class SquealError(RuntimeError):
    """A computation failed (numerical trouble, with the time and the cause), or was interrupted."""

class ScenarioError(ValueError):
    """Bad input: the message names the offending key and value (the CLI's exit code 2)."""

def scenarios() -> List[str]: ...
def scenario_doc(kind: str, text: str, sets: List[str]) -> Tuple[str, str]: ...
def simulate(
    kind: str,
    text: str,
    sets: List[str],
    duration: Optional[float] = None,
    out: Optional[str] = None,
    formats: List[str] = ...,
    plots: bool = True,
    wav: bool = False,
) -> Dict[str, Any]: ...
def plot(
    run_dir: str,
    window: str = "hann",
    segment: int = ...,
    overlap: float = 0.5,
    amplitude: bool = False,
    signals: List[str] = ...,
    fmax: Optional[float] = None,
    frange: Optional[str] = None,
    log_f: bool = False,
) -> List[str]: ...
def stability(kind: str, text: str, sets: List[str], levers: bool, out: Optional[str] = None) -> Dict[str, Any]: ...
def stability_map(
    kind: str,
    text: str,
    sets: List[str],
    x: Tuple[str, float, float, int],
    y: Tuple[str, float, float, int],
    log_x: bool,
    log_y: bool,
    transient: bool,
    duration: Optional[float] = None,
    threads: Optional[int] = None,
    shard: Optional[Tuple[int, int]] = None,
    out: Optional[str] = None,
) -> Dict[str, Any]: ...
def critical(
    kind: str, text: str, sets: List[str], name: str, lo: float, hi: float, grid: int
) -> str: ...
def sweep(
    kind: str,
    text: str,
    sets: List[str],
    param: Tuple[str, float, float, int],
    shard: Optional[Tuple[int, int]] = None,
    out: Optional[str] = None,
) -> Dict[str, Any]: ...
def cycle(
    kind: str,
    text: str,
    sets: List[str],
    settle_steps: int,
    settle_time: float,
    settle_tol: float,
    section: Optional[str] = None,
    out: Optional[str] = None,
) -> Dict[str, Any]: ...
def branch(
    kind: str, text: str, sets: List[str], param: Tuple[str, float, float, int], out: Optional[str] = None
) -> str: ...
def hb(
    kind: str,
    text: str,
    sets: List[str],
    harmonics: int,
    settle_steps: int,
    settle_time: float,
    settle_tol: float,
    guess: str,
    out: Optional[str] = None,
) -> Dict[str, Any]: ...
def hb_branch(
    kind: str,
    text: str,
    sets: List[str],
    param: Tuple[str, float, float, int],
    harmonics: int,
    settle_steps: int,
    settle_time: float,
    settle_tol: float,
    out: Optional[str] = None,
) -> str: ...
def nma(
    kind: str,
    text: str,
    sets: List[str],
    mode: int,
    amplitudes: Tuple[float, float, int],
    harmonics: int,
    out: Optional[str] = None,
) -> str: ...
def validate(filter: Optional[str] = None) -> str: ...
def inspect(kind: str, text: str, sets: List[str]) -> str: ...
def reduce(kind: str, text: str, sets: List[str]) -> Dict[str, Any]: ...
def listen(
    kind: str,
    text: str,
    sets: List[str],
    duration: Optional[float],
    signal: Optional[str],
    gain: float,
    transpose: float,
    float: bool,
    file_name: str,
) -> Dict[str, Any]: ...
def reproduce(
    duration_scale: float = 1.0,
    figures: bool = True,
    shard: Optional[Tuple[int, int]] = None,
    out: Optional[str] = None,
) -> Tuple[str, str, Optional[str]]: ...
def merge(dirs: List[str], out: str) -> Tuple[str, Dict[str, Any]]: ...
def slurm(
    study: str,
    kind: str,
    text: str,
    sets: List[str],
    program: List[str],
    args: List[str],
    tasks: int,
    x: Optional[Tuple[str, float, float, int]] = None,
    y: Optional[Tuple[str, float, float, int]] = None,
    log_x: bool = False,
    log_y: bool = False,
    transient: bool = False,
    duration: Optional[float] = None,
    param: Optional[Tuple[str, float, float, int]] = None,
    duration_scale: float = 1.0,
    out: Optional[str] = None,
    partition: Optional[str] = None,
    time: Optional[str] = None,
    cpus_per_task: Optional[int] = None,
    jobs: Optional[str] = None,
    submit: bool = False,
    extra: List[Tuple[str, str]] = ...,
) -> Dict[str, Any]: ...
