#!/usr/bin/env python3
"""An independent complex eigenvalue analysis (CEA) of a lumped scenario with
[matrices], in NumPy/SciPy, to check squeal's `stability` against.

Reads the scenario TOML and its Matrix Market files, solves steady sliding
(every contact closed, Coulomb friction, no follower force: one linear
solve) and linearises about it:

    K_eff = K + sum_springs k a a^T + sum_contacts k n n^T + s mu k t n^T
    C_eff = C + sum_springs c a a^T + sum_contacts c n n^T + s mu c t n^T

(a Coulomb contact's friction F_t = s mu F_n acts as -F_t t), then prints
the steady state's contact forces and the eigenvalues of
[[0, I], [-M^-1 K_eff, -M^-1 C_eff]] sorted by growth rate, as JSON.

    python3 cea.py two-pad/brake.toml --set mu=0.6 > eig.json

--repeat N does the linear algebra (steady solve, M^-1, state matrix,
eigenvalues) N times, for timing against the N analyses of squeal's levers.

Element values may be expressions of [params] (evaluated here with Python's
arithmetic); --set sets a parameter (no dot) or an element key.
"""

import json
import os
import sys
import tomllib

import numpy as np
import scipy.io
import scipy.linalg


def comb(terms, index, n):
    v = np.zeros(n)
    for name, c in terms.items():
        v[index[name]] += c
    return v


def main():
    path = sys.argv[1]
    sets = {}
    repeat = 1
    args = sys.argv[2:]
    while args:
        if args[0] == "--repeat":
            repeat = int(args[1])
            args = args[2:]
        elif args[0] == "--set":
            k, v = args[1].split("=")
            sets[k] = float(v)
            args = args[2:]
        else:
            raise SystemExit(f"unknown argument {args[0]}")
    with open(path, "rb") as f:
        sc = tomllib.load(f)
    params = dict(sc.get("params", {}))
    params.update({k: v for k, v in sets.items() if "." not in k})

    def val(x):
        """A number, or an expression of [params] (arithmetic only)."""
        if isinstance(x, str):
            return float(eval(x.replace("^", "**"), {"__builtins__": {}}, params))
        return float(x)

    base = os.path.dirname(path)
    mats = {k: scipy.io.mmread(os.path.join(base, v)).toarray() for k, v in sc["matrices"].items()}
    dofs = sc["dofs"]
    n = len(dofs)
    index = {d: i for i, d in enumerate(dofs)}
    m = mats.get("M", np.zeros((n, n))).copy()
    k = mats.get("K", np.zeros((n, n))).copy()
    c = mats.get("C", np.zeros((n, n))).copy()
    for d, mass in sc.get("masses", {}).items():
        m[index[d], index[d]] += val(mass)
    b = np.zeros(n)
    for s in sc.get("spring", []):
        a = comb(s["on"], index, n)
        k += val(s["k"]) * np.outer(a, a)
        c += val(s.get("c", 0.0)) * np.outer(a, a)
    for f in sc.get("force", []):
        b += val(f["value"]) * comb(f["on"], index, n)
    ks, cs = k.copy(), c.copy()
    contacts = []
    for ct in sc.get("contact", []):
        name = ct["name"]
        law = ct.get("friction")
        assert law == "coulomb", "this check handles Coulomb friction only"
        mu_k = sets.get(f"{name}.mu_k", val(ct["mu_k"]))
        kc = sets.get(f"{name}.k", val(ct["k"]))
        cc = sets.get(f"{name}.c", val(ct.get("c", 0.0)))
        v = val(ct["V"])
        s = 1.0 if v >= 0 else -1.0
        nv = comb(ct["normal"], index, n)
        tv = comb(ct["tangent"], index, n)
        assert ct.get("alpha", 0.0) == 0.0
        ks += kc * np.outer(nv, nv) + s * mu_k * kc * np.outer(tv, nv)
        cs += cc * np.outer(nv, nv) + s * mu_k * cc * np.outer(tv, nv)
        contacts.append((name, kc, nv))
    for _ in range(repeat):
        q = np.linalg.solve(ks, b)
        minv = np.linalg.inv(m)
        a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ ks, -minv @ cs]])
        lam = scipy.linalg.eigvals(a)
    order = np.lexsort((lam.imag, -lam.real))
    lam = lam[order]
    out = {
        "normal_forces": {name: float(kc * nv @ q) for name, kc, nv in contacts},
        "q": q.tolist(),
        "eigenvalues": [[float(x.real), float(x.imag)] for x in lam],
    }
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
