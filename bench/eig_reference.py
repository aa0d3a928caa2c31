#!/usr/bin/env python3
"""50-digit reference eigenvalues of the disc-pad state matrix (MODEL.md §5).

The matrix is the analytic Jacobian `DiscPad::jacobian` of squeal-core at the
steady-sliding equilibrium with the default parameters (V = 1, N = 500, thesis
friction law), exactly as the f64 entries Rust prints with `{:?}` (shortest
round-trip representation, so Python parses the very same doubles). The
eigenvalues are computed in 50-digit arithmetic by mpmath (QR on the exact
binary entries), so they are the exact eigenvalues of that f64 matrix to far
more digits than a double holds.

Used by crates/squeal-core/tests/stability.rs
(`disc_pad_default_eigenvalues_match_50_digit_reference`), which also checks
that the Jacobian still has exactly these entries.

Run: python3 bench/eig_reference.py
"""
import mpmath

mpmath.mp.dps = 50

J = [
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
    [-1000000000.0, -0.0, -397516666.6666667, 397516666.6666667,
     2.1333333333332614, -3.1333333333332614, -0.01870666666666667, 0.01870666666666667],
    [0.0, -17000000000.0, 3975166666.6666665, -3975166666.6666665,
     -31.33333333333261, 29.33333333333261, 0.1870666666666667, -0.1870666666666667],
    [-0.0, -0.0, -4258000000.0, 4250000000.0, 0.0, -0.0, -1.2, 0.2],
    [0.0, 0.0, 42500000000.0, -42500000000.0, 0.0, 0.0, 2.0, -2.0],
]

A = mpmath.matrix([[mpmath.mpf(x) for x in row] for row in J])
ev, er = mpmath.eig(A, left=False, right=True)
# Refine: one Newton step on det(A − λI) is unnecessary at 50 digits; instead
# report the residual ‖(A − λI)x‖/‖x‖ as a check of the QR result.
rows = []
for k, lam in enumerate(ev):
    x = er[:, k]
    r = mpmath.norm(A * x - lam * x) / mpmath.norm(x)
    rows.append((lam, r))
rows.sort(key=lambda t: (-t[0].real, -t[0].imag))
for lam, r in rows:
    print(f"({mpmath.nstr(lam.real, 25)}, {mpmath.nstr(lam.imag, 25)}),  # residual {mpmath.nstr(r, 3)}")
