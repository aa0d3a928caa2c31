"""``python -m squeal``: the sharded studies from the command line, for the
job scripts :func:`squeal.slurm` writes (a machine with the wheel and no
``squeal`` binary runs them the same way).

    python -m squeal map SCENARIO [--set K=V]... --x NAME=LO:HI:N --y NAME=LO:HI:N
        [--log-x] [--log-y] [--transient] [--duration S] [--shard K/N] [--out DIR]
    python -m squeal sweep SCENARIO [--set K=V]... --param NAME=LO:HI:N [--shard K/N] [--out DIR]
    python -m squeal reproduce [--duration-scale F] [--no-figures] [--shard K/N] [--out DIR]
    python -m squeal merge DIR... --out DIR

The flags are the ``squeal`` CLI's; a scenario ``FILE.json`` is a scenario
dict. Bad input ends with one line and exit code 2, a failed computation
with exit code 1.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any, Dict, List, Optional, Sequence, Tuple

import squeal


def _axis(text: str, flag: str) -> Tuple[str, float, float, int]:
    try:
        name, rng = text.split("=", 1)
        lo, hi, n = rng.split(":")
        return (name, float(lo), float(hi), int(n))
    except ValueError:
        raise squeal.ScenarioError(f"{flag} {text}: expected NAME=LO:HI:N") from None


def _shard(text: Optional[str]) -> Optional[Tuple[int, int]]:
    if text is None:
        return None
    try:
        k, n = text.split("/")
        return (int(k), int(n))
    except ValueError:
        raise squeal.ScenarioError(f"--shard {text}: expected K/N, e.g. 0/4") from None


def _scenario(text: str) -> Any:
    if text.endswith(".json"):
        with open(text, encoding="utf-8") as f:
            return json.load(f)
    return text


def _sets(pairs: Sequence[str]) -> Dict[str, str]:
    out = {}
    for p in pairs:
        k, eq, v = p.partition("=")
        if not eq:
            raise squeal.ScenarioError(f"--set {p}: expected NAME=VALUE")
        out[k] = v
    return out


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m squeal", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    m = sub.add_parser("map", help="stability over a grid of two parameters")
    s = sub.add_parser("sweep", help="eigenvalues tracked along one parameter")
    for p in (m, s):
        p.add_argument("scenario")
        p.add_argument("--set", action="append", default=[], dest="sets")
    m.add_argument("--x", required=True)
    m.add_argument("--y", required=True)
    m.add_argument("--log-x", action="store_true")
    m.add_argument("--log-y", action="store_true")
    m.add_argument("--transient", action="store_true")
    m.add_argument("--duration", type=float)
    s.add_argument("--param", required=True)
    r = sub.add_parser("reproduce", help="the thesis reproduced")
    r.add_argument("--duration-scale", type=float, default=1.0)
    r.add_argument("--no-figures", action="store_true")
    for p in (m, s, r):
        p.add_argument("--shard")
        p.add_argument("--out")
    g = sub.add_parser("merge", help="the shards of one study gathered")
    g.add_argument("dirs", nargs="+")
    g.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    try:
        result: Any
        if a.command == "map":
            result = squeal.map(
                _scenario(a.scenario), x=_axis(a.x, "--x"), y=_axis(a.y, "--y"),
                log_x=a.log_x, log_y=a.log_y, transient=a.transient, duration=a.duration,
                shard=_shard(a.shard), out=a.out, set=_sets(a.sets),
            )
        elif a.command == "sweep":
            result = squeal.sweep(
                _scenario(a.scenario), param=_axis(a.param, "--param"),
                shard=_shard(a.shard), out=a.out, set=_sets(a.sets),
            )
        elif a.command == "reproduce":
            result = squeal.reproduce(
                duration_scale=a.duration_scale, figures=not a.no_figures,
                shard=_shard(a.shard), out=a.out,
            )
        else:
            result = squeal.merge(a.dirs, out=a.out)
    except squeal.ScenarioError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except squeal.SquealError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    dest = result.get("out") if isinstance(result, dict) else result.attrs.get("out")
    print(f"{a.command}: output {dest}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
