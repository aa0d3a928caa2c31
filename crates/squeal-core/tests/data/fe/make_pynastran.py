"""Write the FE-format fixtures of squeal-core's DMIG and Harwell-Boeing tests
with independent writers: pyNastran 1.4.1 for DMIG, SciPy for Harwell-Boeing
RUA and Matrix Market (the reference values).

Run from this folder with a venv that has them (never a runtime dependency):

    python3 -m venv /work/venv-pynastran
    /work/venv-pynastran/bin/pip install "numpy<2" pyNastran==1.4.1
    /work/venv-pynastran/bin/python make_pynastran.py

The matrices: a symmetric K and an unsymmetric U on six dofs, grid 1203's
components 1, 2, 3, grid 88's 3, scalar point 7 and grid 5's 6, with values
that need every digit of a double.

- kaax_small.bdf   pyNastran, small field, TIN=1 (single: about 6 digits)
- kaax_large.bdf   pyNastran, large field, TIN=2 (16-character fields: 10 digits)
- kaax_free.bdf    this script, free field, TIN=2, repr() of each double
                   (pyNastran has no free-field writer; its reader is checked
                   to read the file back to the same values)
- k.mtx, u.mtx     SciPy mmwrite, the reference values in the order of dofs.txt
- u_rua.rb, k_rua.rb  SciPy hb_write (RUA, both triangles)
- k_rsa.matrix, k_rsa.mapping  this script: ANSYS HBMAT's layout (RSA, lower
                   triangle, (I14)/(d25.15), a right-hand side, a mapping file)
"""
import numpy as np
import scipy.io
import scipy.sparse as sp
from pyNastran.bdf.bdf import BDF, read_bdf

DOFS = [(1203, 1), (1203, 2), (1203, 3), (88, 3), (7, 0), (5, 6)]
ANSYS = [(1203, "UX"), (1203, "UY"), (1203, "UZ"), (88, "UZ"), (7, "PRES"), (5, "ROTZ")]
n = len(DOFS)

rng = np.random.default_rng(26)
a = rng.standard_normal((n, n)) * 1.0e3
k = a @ a.T + np.diag(rng.uniform(1.0e5, 2.0e6, n))
for i, j in [(3, 0), (4, 1), (5, 2), (5, 0)]:  # some structural zeros
    k[i, j] = k[j, i] = 0.0
k[4, 4] *= 1.0e-3
u = k.copy()
u[0, 1] += 123.456789012345678
u[3, 2] -= 9.87654321e-3
u[2, 5] = 0.1234567890123457  # a one-sided entry


def entries(m, lower):
    """(GCj, GCi, Real) column by column, lower triangle or all."""
    gcj, gci, real = [], [], []
    for j in range(n):
        for i in range(j if lower else 0, n):
            if m[i, j] != 0.0:
                gcj.append(DOFS[j])
                gci.append(DOFS[i])
                real.append(float(m[i, j]))
    return gcj, gci, real


for name, tin, size in [("small", 1, 8), ("large", 2, 16)]:
    model = BDF(debug=False)
    model.add_dmig("KAAX", 6, tin, tin, 0, None, *entries(k, True))
    model.add_dmig("UAAX", 1, tin, tin, 0, None, *entries(u, False))
    model.write_bdf(f"kaax_{name}.bdf", size=size, is_double=(tin == 2), enddata=True)

with open("kaax_free.bdf", "w") as f:
    f.write("$ free-field DMIG, written by the generating script of this folder\n")
    for mname, ifo, m, lower in [("KAAX", 6, k, True), ("UAAX", 1, u, False)]:
        f.write(f"DMIG,{mname},0,{ifo},2,2\n")
        gcj, gci, real = entries(m, lower)
        for col in dict.fromkeys(gcj):
            fields = [mname, str(col[0]), str(col[1]), ""]
            for cj, ci, v in zip(gcj, gci, real):
                if cj == col:
                    fields += [str(ci[0]), str(ci[1]), repr(v), ""]
            lines = [fields[:8]] + [fields[p:p + 8] for p in range(8, len(fields), 8)]
            f.write("DMIG," + ",".join(lines[0]) + "\n")
            for l in lines[1:]:
                f.write("+," + ",".join(l) + "\n")
    f.write("ENDDATA\n")

# pyNastran reads its own files and the free-field one back
for name, tol in [("small", 1e-3), ("large", 1e-9), ("free", 0.0)]:
    model = read_bdf(f"kaax_{name}.bdf", punch=True, debug=None)
    for mname, ref in [("KAAX", k), ("UAAX", u)]:
        d = model.dmig[mname]
        got = np.zeros((n, n))
        for gj, gi, v in zip(d.GCj, d.GCi, d.Real):
            got[DOFS.index(tuple(gi)), DOFS.index(tuple(gj))] = v
        if d.matrix_form == 6:
            got = got + np.tril(got, -1).T
        err = np.max(np.abs(got - ref) / np.maximum(np.abs(ref), 1e-300) * (ref != 0))
        assert err <= tol, (name, mname, err)
        print(f"pyNastran reads kaax_{name}.bdf {mname}: max relative error {err:.2e}")

scipy.io.mmwrite("k.mtx", sp.coo_matrix(k), precision=17)
scipy.io.mmwrite("u.mtx", sp.coo_matrix(u), precision=17)
scipy.io.hb_write("k_rua.rb", sp.csc_matrix(k))
scipy.io.hb_write("u_rua.rb", sp.csc_matrix(u))
with open("dofs.txt", "w") as f:
    f.write("".join(f"{g}_{c}\n" for g, c in DOFS))


def d25(x):
    """Fortran D25.15: 0.xxxxxxxxxxxxxxxD+ee (ANSYS HBMAT's values)."""
    if x == 0.0:
        return f"{'0.000000000000000D+00':>25}"
    e = int(np.floor(np.log10(abs(x)))) + 1
    m = x / 10.0**e
    if abs(m) >= 1.0:  # rounding up to 1.0
        m, e = m / 10.0, e + 1
    return f"{('-' if m < 0 else '') + f'{abs(m):.15f}'}D{e:+03d}".rjust(25)


csc = sp.csc_matrix(np.tril(k))
ptr, ind, val = csc.indptr + 1, csc.indices + 1, csc.data
rhs = np.zeros(n)
cards = [len(ptr), len(ind), len(val), n]
with open("k_rsa.matrix", "w") as f:
    f.write(f"{'Stiffness matrix from make_pynastran.py in ANSYS HBMAT layout':<72}{'':<8}\n")
    f.write("".join(f"{c:>14}" for c in [sum(cards)] + cards) + "\n")
    f.write(f"{'RSA':<14}{n:>14}{n:>14}{len(val):>14}{0:>14}\n")
    f.write(f"{'(I14)':<16}{'(I14)':<16}{'(d25.15)':<20}{'(d25.15)':<20}\n")
    f.write(f"{'F':<14}{1:>14}{n:>14}\n")
    for x in list(ptr) + list(ind):
        f.write(f"{x:>14}\n")
    for x in list(val) + list(rhs):
        f.write(f"{d25(x):>25}\n")
with open("k_rsa.mapping", "w") as f:
    f.write("    Matrix Eqn          Node    DOF     \n")
    for e, (node, lab) in enumerate(ANSYS, 1):
        f.write(f"{e:>14}{node:>14}    {lab:<4}\n")
print("written")
