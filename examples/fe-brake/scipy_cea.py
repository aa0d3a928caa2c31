#!/usr/bin/env python3
"""The reduced complex eigenvalue analysis (CEA) of a large FE brake in
SciPy, stage by stage and timed: the independent side of squeal's
benchmark of 10^5-dof models (BENCHMARKS.md), done the way FE packages do
it and the way squeal's `[modal]` analysis does:

1. read the scenario and its Matrix Market files (sparse throughout);
2. linearise steady sliding (every contact closed, Coulomb friction):
       K_eff = K + sum_c k n n^T + s mu k t n^T,  C_eff likewise with c;
3. the real modes of (K_s, M), K_s = (K_eff + K_eff^T)/2, every one up to
   --cutoff-hz, by ARPACK shift-invert Lanczos (scipy.sparse.linalg.eigsh,
   sigma = -(2 pi * cutoff/5)^2, k grown until a mode above the cut-off);
4. the static correction at the dofs where K_eff or C_eff is non-symmetric:
   (K_s + (2 pi 1 Hz)^2 M)^-1 e_j, M-orthogonalised against the modes
   (twice) and Rayleigh-Ritz-diagonalised in K_s;
5. K_eff, C_eff projected on the basis and the 2m x 2m state matrix's
   eigenvalues by scipy.linalg.eig.

Prints JSON: dofs, nonzeros, modes, static_vectors, basis_max_hz, the
unstable eigenvalues (re > 1e-12 |lambda|, im >= 0), seconds per stage and
the peak memory.

    python3 scipy_cea.py disc-100804/brake.toml --cutoff-hz 25000

Only NumPy and SciPy are used; this is a check, never a dependency.
"""

import argparse
import json
import math
import os
import resource
import time
import tomllib

import numpy as np
import scipy.io
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla


def combination(terms, index, n):
    rows = [index[d] for d in terms]
    return sp.csc_matrix((list(terms.values()), (rows, [0] * len(rows))), shape=(n, 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario")
    ap.add_argument("--cutoff-hz", type=float, default=40000.0)
    ap.add_argument("--set", action="append", default=[], help="a [params] value: mu=0.6")
    a = ap.parse_args()
    seconds = {}
    t0 = time.perf_counter()
    with open(a.scenario, "rb") as f:
        sc = tomllib.load(f)
    params = dict(sc.get("params", {}))
    for kv in a.set:
        k, v = kv.split("=")
        params[k] = float(v)

    def val(x):
        if isinstance(x, str):
            return float(eval(x.replace("^", "**"), {"__builtins__": {}}, params))
        return float(x)

    base = os.path.dirname(a.scenario)
    mats = {k: sp.csc_matrix(scipy.io.mmread(os.path.join(base, v))) for k, v in sc["matrices"].items()}
    dofs = sc["dofs"]
    n = len(dofs)
    index = {d: i for i, d in enumerate(dofs)}
    seconds["read"] = time.perf_counter() - t0

    t = time.perf_counter()
    m = mats["M"]
    k = mats["K"].copy()
    c = mats.get("C", sp.csc_matrix((n, n))).copy()
    b = np.zeros(n)
    for f in sc.get("force", []):
        b += val(f["value"]) * combination(f["on"], index, n).toarray().ravel()
    contact_dofs = set()
    for ct in sc.get("contact", []):
        assert ct.get("friction") == "coulomb" and ct.get("alpha", 0.0) == 0.0
        mu_k, kc, cc = val(ct["mu_k"]), val(ct["k"]), val(ct.get("c", 0.0))
        s = 1.0 if val(ct["V"]) >= 0 else -1.0
        nv = combination(ct["normal"], index, n)
        tv = combination(ct["tangent"], index, n)
        k = k + kc * (nv @ nv.T) + s * mu_k * kc * (tv @ nv.T)
        c = c + cc * (nv @ nv.T) + s * mu_k * cc * (tv @ nv.T)
        contact_dofs.update(index[d] for d in list(ct["normal"]) + list(ct["tangent"]))
    k, c = sp.csc_matrix(k), sp.csc_matrix(c)
    q = sla.spsolve(k, b)  # steady sliding (the forces' static response)
    ks = sp.csc_matrix((k + k.T) / 2)
    seconds["linearise"] = time.perf_counter() - t

    t = time.perf_counter()
    wc = 2 * math.pi * a.cutoff_hz
    sigma = -((wc / 5) ** 2)
    want = 50
    while True:
        w2, phi = sla.eigsh(ks, k=min(want, n - 2), M=m, sigma=sigma, which="LM")
        order = np.argsort(w2)
        w2, phi = w2[order], phi[:, order]
        if w2[-1] > wc**2 or want >= n - 2:
            break
        want *= 2
    keep = w2 <= wc**2
    w2, phi = w2[keep], phi[:, keep]
    seconds["real modes"] = time.perf_counter() - t

    t = time.perf_counter()
    skew = sp.coo_matrix(abs(k - k.T) + abs(c - c.T))
    scale = max(abs(k).max(), 1e-300)
    j = sorted(set(skew.row[np.abs(skew.data) > 1e-12 * scale]) | set(skew.col[np.abs(skew.data) > 1e-12 * scale]))
    rhs = np.zeros((n, len(j)))
    rhs[j, np.arange(len(j))] = 1.0
    lu = sla.splu(sp.csc_matrix(ks + (2 * math.pi) ** 2 * m))
    r = lu.solve(rhs)
    mphi = m @ phi
    kept = []
    for col in r.T:
        v = col.copy()
        norm0 = math.sqrt(v @ (m @ v))
        for _ in range(2):
            v -= phi @ (mphi.T @ v)
            for u in kept:
                v -= u * (u @ (m @ v))
        norm = math.sqrt(max(v @ (m @ v), 0.0))
        if norm > 1e-8 * norm0:
            kept.append(v / norm)
    if kept:
        rr = np.array(kept).T
        small = rr.T @ (ks @ rr)
        lam_s, wv = np.linalg.eigh((small + small.T) / 2)
        basis = np.hstack([phi, rr @ wv])
    else:
        basis = phi
    seconds["static correction"] = time.perf_counter() - t

    t = time.perf_counter()
    kr = basis.T @ (k @ basis)
    cr = basis.T @ (c @ basis)
    nb = basis.shape[1]
    state = np.block([[np.zeros((nb, nb)), np.eye(nb)], [-kr, -cr]])
    lam = scipy.linalg.eigvals(state)
    seconds["reduced eig"] = time.perf_counter() - t
    seconds["total"] = time.perf_counter() - t0
    unstable = sorted(
        (x for x in lam if x.real > 1e-12 * abs(x) and x.imag >= 0), key=lambda x: -x.real
    )
    out = {
        "dofs": n,
        "nonzeros": int(mats["K"].nnz),
        "modes": int(phi.shape[1]),
        "static_vectors": len(kept),
        "basis_max_hz": float(math.sqrt(max(w2[-1], 0.0)) / (2 * math.pi)),
        "steady_q_norm": float(np.linalg.norm(q)),
        "unstable": [{"re": float(x.real), "im": float(x.imag), "freq_hz": float(x.imag / (2 * math.pi))} for x in unstable],
        "seconds": {key: round(v, 2) for key, v in seconds.items()},
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
