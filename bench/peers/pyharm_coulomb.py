#!/usr/bin/env python3
"""pyHarm side of bench/peers (squeal issue 29): the forced Coulomb oscillator

    m x'' + c x' + k x + mu*N*sign(x') = F cos(w t)

by pyHarm's harmonic balance with its DLFT friction element (exact Coulomb
law with stick, penalty eps), continued in the forcing frequency.
Run it in pyHarm's own venv (never a squeal dependency):

    /tmp/pyharm-venv/bin/python bench/peers/pyharm_coulomb.py --H 20 --nti 1024 \
        --eps 1e7 --c 0 --lo-hz 9.5493 --hi-hz 15.1197 --ds 0.25 --out bench/peers/x.csv

The analysis is run twice in one process: the first run includes numba's and
jax's compilation (JIT), the second is the warm time. Both are printed.
Amplitude = half the peak-to-peak of x over a period (squeal's `amplitude`),
evaluated on 4096 points of the Fourier series; `amp_h1` the first harmonic.
"""
import argparse, csv, logging, os, sys, tempfile, time, warnings

import numpy as np

warnings.filterwarnings("ignore")
# pyHarm writes ./.pyHarm/context.json into the working directory: run it
# in a scratch directory, never in the repository.
_OUT = [os.path.abspath(v) if i and sys.argv[i - 1] == "--out" else v for i, v in enumerate(sys.argv)]
sys.argv = _OUT
os.chdir(tempfile.mkdtemp(prefix="pyharm-"))
import pyHarm  # noqa: E402


def build(a):
    sub = {"sub": [0]}
    con = {
        "mass": {"type": "GOElement", "dto": 2, "xo": 1, "k": a.m, "connect": sub, "dirs": [0]},
        "spring": {"type": "LinearSpring", "k": a.k, "connect": sub, "dirs": [0]},
        "force": {"type": "CosinusForcing", "amp": a.F, "connect": sub, "dirs": [0]},
        "fric": {"type": "DLFTFriction", "mu": 1.0, "N0": a.muN, "eps": a.eps,
                 "connect": sub, "dirs": [0]},
    }
    if a.c:
        con["damp"] = {"type": "LinearDamper", "k": a.c, "connect": sub, "dirs": [0]}
    return {
        "system": {"type": "Base", "nh": a.H, "nti": a.nti},
        "substructures": {"sub": {"type": "onlydofs", "nnodes": 1, "ndofs": 1}},
        "connectors": con,
        "analysis": {"frf": {
            "study": "frf",
            "puls_inf": 2 * np.pi * a.lo_hz, "puls_sup": 2 * np.pi * a.hi_hz,
            "ds0": a.ds, "ds_max": a.ds, "ds_min": 1e-8,
            "stepsizer": a.stepsizer, "verbose": False,
        }},
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--H", type=int, default=20)
    p.add_argument("--nti", type=int, default=1024)
    p.add_argument("--eps", type=float, default=1e7)
    p.add_argument("--m", type=float, default=1.0)
    p.add_argument("--k", type=float, default=1.0e4)
    p.add_argument("--c", type=float, default=0.0)
    p.add_argument("--F", type=float, default=10.0)
    p.add_argument("--muN", type=float, default=3.0)
    p.add_argument("--lo-hz", type=float, required=True)
    p.add_argument("--hi-hz", type=float, required=True)
    p.add_argument("--ds", type=float, default=1.0, help="arc-length step (≈ rad/s here)")
    p.add_argument("--stepsizer", default="acceptance")
    p.add_argument("--runs", type=int, default=2)
    p.add_argument("--out", required=True)
    a = p.parse_args()
    logging.disable(logging.CRITICAL)

    times = []
    for _ in range(a.runs):
        m = pyHarm.Maestro(build(a))
        t0 = time.perf_counter()
        m.operate()
        times.append(time.perf_counter() - t0)
    ana = m.nls["frf"]
    sols = [s for s in ana.SolList if s.flag_accepted]
    th = np.linspace(0.0, 2 * np.pi, 4096, endpoint=False)
    k = np.arange(1, a.H + 1)
    C, S = np.cos(np.outer(th, k)), np.sin(np.outer(th, k))
    with open(a.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["omega_rad_s", "freq_hz", "amplitude", "amp_h1"])
        for s in sols:
            x = s.x
            q = x[0] + C @ x[1:2 * a.H:2] + S @ x[2:2 * a.H + 1:2]
            w.writerow([f"{x[-1]:.12g}", f"{x[-1] / (2 * np.pi):.12g}",
                        f"{(q.max() - q.min()) / 2:.12g}", f"{np.hypot(x[1], x[2]):.12g}"])
    print(f"PYHARM H={a.H} nti={a.nti} eps={a.eps:g} points={len(sols)} "
          f"(of {len(ana.SolList)}) times_s=" + ",".join(f"{t:.3f}" for t in times))


if __name__ == "__main__":
    main()
