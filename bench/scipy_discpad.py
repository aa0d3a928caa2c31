#!/usr/bin/env python3
"""The default disc–pad run in SciPy, for the peer comparison in BENCHMARKS.md.

Same equations as squeal (MODEL.md §3–4, defaults of §2), integrated by
SciPy's DOP853 at rtol 1e-8 with per-state atol (1e-16 m, 1e-11 m/s) and
terminal events on the sliding velocity and the contact force, restarting in
the new mode after each. Not part of CI:

    pip install scipy numpy
    python3 bench/scipy_discpad.py --duration 0.1

prints wall seconds per simulated second. (Note: SciPy's events use a sign
test at the ends of each step, so once reversals start it misses excursions
shorter than a step; the timing is all this script is for.)
"""
import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

m_d, m_p = 1.0, 0.1
k_dx, c_dx, k_dy, c_dy = 1.0e9, 1.0, 8.0e6, 1.0
k_px, c_px, k_py, c_py = 1.7e9, 0.2, 4.25e9, 0.2
N, V, alpha = 500.0, 1.0, 0.0
f0, f1, Uc = 0.1, 1.0 / 15.0, 50.0 / 3.0


def mu(v):
    return f0 * (1.0 - f1 * v * (1.0 - v / (2.0 * Uc)))


def rhs(t, z, s):
    x_d, x_p, y_d, y_p, u_d, u_p, w_d, w_p = z
    f_y = k_py * (y_d - y_p) + c_py * (w_d - w_p)
    v = V + u_d - u_p
    f_t = s * mu(abs(v)) * f_y
    f_f = alpha * f_t * y_d
    return [u_d, u_p, w_d, w_p,
            (-k_dx * x_d - c_dx * u_d - f_t) / m_d,
            (-k_px * x_p - c_px * u_p + f_t) / m_p,
            (-k_dy * y_d - c_dy * w_d - f_y + f_f) / m_d,
            (f_y - N - f_f) / m_p]


def run(duration):
    atol = np.array([1e-16] * 4 + [1e-11] * 4)
    z = np.zeros(8)
    t, s, steps, nfev = 0.0, 1.0, 0, 0

    def slip_zero(t, z, s):
        return V + z[4] - z[5]
    slip_zero.terminal = True

    while t < duration:
        slip_zero.direction = -s
        sol = solve_ivp(rhs, (t, duration), z, method="DOP853", rtol=1e-8, atol=atol,
                        args=(s,), events=slip_zero, dense_output=False)
        nfev += sol.nfev
        steps += len(sol.t) - 1
        t, z = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:
            s = -s  # reversal (sticks ignored: timing only)
    return steps, nfev, z


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=0.1)
    a = ap.parse_args()
    t0 = time.perf_counter()
    steps, nfev, z = run(a.duration)
    wall = time.perf_counter() - t0
    print(f"scipy DOP853: {a.duration} s simulated in {wall:.2f} s wall "
          f"({wall / a.duration:.1f} s per simulated second), {steps} steps, {nfev} RHS evaluations")
    # The end state, to compare with squeal's (`speed_probe state 1e-12` at 0.3 s).
    print("end state vx_p = %.12e, vy_p = %.12e" % (z[5], z[7]))
