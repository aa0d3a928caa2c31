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
def simulate(kind: str, text: str, sets: List[str], duration: Optional[float] = None) -> Dict[str, Any]: ...
def stability(kind: str, text: str, sets: List[str], levers: bool) -> Dict[str, Any]: ...
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
) -> Dict[str, Any]: ...
def critical(
    kind: str, text: str, sets: List[str], name: str, lo: float, hi: float, grid: int
) -> str: ...
def sweep(kind: str, text: str, sets: List[str], param: Tuple[str, float, float, int]) -> Dict[str, Any]: ...
def cycle(
    kind: str,
    text: str,
    sets: List[str],
    settle_steps: int,
    settle_time: float,
    settle_tol: float,
    section: Optional[str] = None,
) -> Dict[str, Any]: ...
def branch(kind: str, text: str, sets: List[str], param: Tuple[str, float, float, int]) -> str: ...
def hb(
    kind: str,
    text: str,
    sets: List[str],
    harmonics: int,
    settle_steps: int,
    settle_time: float,
    settle_tol: float,
    guess: str,
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
def reproduce(duration_scale: float = 1.0) -> Tuple[str, str]: ...
