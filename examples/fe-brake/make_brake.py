#!/usr/bin/env python3
"""A small FE disc brake, written as squeal scenarios with Matrix Market files.

The disc is a ring of mean radius R cut open into a straight beam of length
2*pi*R with periodic ends (curvature neglected), meshed with N two-node
elements. Each node n has three dofs:

    n_1  circumferential (in-plane) displacement u   (bar:   EA)
    n_3  out-of-plane displacement w                 (beam:  EI, Euler-Bernoulli)
    n_5  rotation theta = dw/ds                      (beam)

with consistent element mass matrices and Rayleigh damping C = a*M + b*K.
The hub holds the ring with springs on u and w at every node. Each pad is a
rigid block with a tangential dof (`<id>_1`) on a caliper spring and a
normal dof (`<id>_3`) pressed by the brake force. A pad touches the disc's
surface at a node: the compression is the normal gap, and the sliding
velocity is V plus the disc surface's tangential velocity, u -/+ (h/2)*theta
(the surface is half a thickness from the beam's axis: friction there bends
the disc, the coupling behind mode-coupling squeal) minus the pad's.

Dofs are named `<node>_<component>` as squeal names the dofs of Nastran,
Abaqus and ANSYS files. Only NumPy and SciPy are used.

    python3 make_brake.py --elements 40 --out .        # writes the two-pad and four-pad scenarios

Every number written depends only on the arguments: the files are the same
on every machine.
"""

import argparse
import math
import os

import numpy as np
import scipy.io
import scipy.sparse as sp


def ring(n_el, radius, thickness, width, e_mod, rho, hub_k):
    """Stiffness and mass of the periodic ring (3 dofs per node)."""
    length = 2.0 * math.pi * radius
    le = length / n_el
    area = width * thickness
    inertia = width * thickness**3 / 12.0
    ndof = 3 * n_el
    k = sp.lil_matrix((ndof, ndof))
    m = sp.lil_matrix((ndof, ndof))
    # Bar (u): stiffness EA/le [[1,-1],[-1,1]], consistent mass rho*A*le/6 [[2,1],[1,2]].
    kb = e_mod * area / le * np.array([[1.0, -1.0], [-1.0, 1.0]])
    mb = rho * area * le / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    # Euler-Bernoulli beam (w1, t1, w2, t2).
    l = le
    kbm = e_mod * inertia / l**3 * np.array(
        [
            [12.0, 6 * l, -12.0, 6 * l],
            [6 * l, 4 * l * l, -6 * l, 2 * l * l],
            [-12.0, -6 * l, 12.0, -6 * l],
            [6 * l, 2 * l * l, -6 * l, 4 * l * l],
        ]
    )
    mbm = rho * area * l / 420.0 * np.array(
        [
            [156.0, 22 * l, 54.0, -13 * l],
            [22 * l, 4 * l * l, 13 * l, -3 * l * l],
            [54.0, 13 * l, 156.0, -22 * l],
            [-13 * l, -3 * l * l, -22 * l, 4 * l * l],
        ]
    )
    for e in range(n_el):
        a, b = e, (e + 1) % n_el
        ub = [3 * a, 3 * b]
        wb = [3 * a + 1, 3 * a + 2, 3 * b + 1, 3 * b + 2]
        for i in range(2):
            for j in range(2):
                k[ub[i], ub[j]] += kb[i, j]
                m[ub[i], ub[j]] += mb[i, j]
        for i in range(4):
            for j in range(4):
                k[wb[i], wb[j]] += kbm[i, j]
                m[wb[i], wb[j]] += mbm[i, j]
    for node in range(n_el):
        k[3 * node, 3 * node] += hub_k
        k[3 * node + 1, 3 * node + 1] += hub_k
    return k, m


def fmt(x):
    return repr(float(x))


def labels_of(names):
    """(node, component) of each dof name `<node>_<component>`."""
    return [tuple(int(x) for x in n.split("_")) for n in names]


def write_dmig(path, mats, names):
    """Nastran DMIG bulk data, free field, form 6 (symmetric: the upper
    triangle by index), real double precision (TIN=2), one card per entry;
    every matrix in one file, chosen by name."""
    lab = labels_of(names)
    with open(path, "w") as f:
        f.write("$ Written by make_brake.py: DMIG, free field, form 6, real double\n")
        for name, mat in mats:
            coo = sp.triu(sp.coo_matrix(mat)).tocoo()
            f.write(f"DMIG,{name},0,6,2,0,,,{mat.shape[0]}\n")
            entries = sorted(zip(coo.col, coo.row, coo.data))
            for j, i, v in entries:
                gj, cj = lab[j]
                gi, ci = lab[i]
                f.write(f"DMIG,{name},{gj},{cj},,{gi},{ci},{float(v)!r}\n")


def write_abaqus(path, mat, names):
    """Abaqus *MATRIX OUTPUT, FORMAT=MATRIX INPUT: `node, dof, node, dof,
    value`, the lower triangle as Abaqus writes it."""
    lab = labels_of(names)
    coo = sp.tril(sp.coo_matrix(mat)).tocoo()
    with open(path, "w") as f:
        for i, j, v in sorted(zip(coo.row, coo.col, coo.data)):
            (gi, ci), (gj, cj) = lab[i], lab[j]
            f.write(f"{gi},{ci}, {gj},{cj}, {float(v):.16e}\n")


ANSYS = {1: "UX", 2: "UY", 3: "UZ", 4: "ROTX", 5: "ROTY", 6: "ROTZ"}


def write_hb_rsa(path, mat, names, title):
    """Harwell-Boeing RSA (the lower triangle column by column, as ANSYS
    HBMAT writes K and M), values (3E26.17), and ANSYS's mapping file
    beside it (same name, .mapping)."""
    csc = sp.tril(sp.csc_matrix(mat)).tocsc()
    csc.sort_indices()
    n = mat.shape[0]
    ptr = [int(x) + 1 for x in csc.indptr]
    ind = [int(x) + 1 for x in csc.indices]
    val = [float(x) for x in csc.data]

    def lines(items, per, width, fmtf):
        return ["".join(fmtf(x).rjust(width) for x in items[k:k + per]) for k in range(0, len(items), per)]

    pl = lines(ptr, 8, 10, str)
    il = lines(ind, 8, 10, str)
    vl = lines(val, 3, 26, lambda x: f"{x:.17E}")
    with open(path, "w") as f:
        f.write(f"{title:<72}{'KEY':<8}\n")
        f.write(f"{len(pl) + len(il) + len(vl):14d}{len(pl):14d}{len(il):14d}{len(vl):14d}{0:14d}\n")
        f.write(f"{'RSA':<14}{n:14d}{n:14d}{len(val):14d}{0:14d}\n")
        f.write(f"{'(8I10)':<16}{'(8I10)':<16}{'(3E26.17)':<20}\n")
        for l in pl + il + vl:
            f.write(l + "\n")
    mapping = os.path.splitext(path)[0] + ".mapping"
    with open(mapping, "w") as f:
        f.write("Matrix Eqn   Node   DOF\n")
        for k, (node, comp) in enumerate(labels_of(names)):
            f.write(f"{k + 1:10d} {node:10d}     {ANSYS[comp]}\n")


def pad_toml(p, surface_normal_dof, tangent, speed):
    """The [[force]] pressing pad `p` and its [[contact]] with the disc:
    the normal gap between the disc surface's dof and the pad's normal dof
    (signed by the pad's side), the given tangential combination."""
    pid, side = p["id"], p["side"]
    if side > 0:
        normal = f"{{ {surface_normal_dof} = 1.0, {pid}_3 = -1.0 }}"
    else:
        normal = f"{{ {pid}_3 = 1.0, {surface_normal_dof} = -1.0 }}"
    return [
        "",
        "[[force]]",
        f'name = "brake_{pid}"',
        f"on = {{ {pid}_3 = 1.0 }}",
        f'value = "{fmt(-side * p["force_share"])}*Fb"',
        "",
        "[[contact]]",
        f'name = "{p["name"]}"',
        f"normal = {normal}",
        f"k = {fmt(p['k_contact'])}",
        f"c = {fmt(p['c_contact'])}",
        'contact = "unilateral"',
        f"tangent = {tangent}",
        f"V = {fmt(speed)}",
        'friction = "coulomb"',
        f'mu_s = "{fmt(p["mu_ratio"] * 1.2)}*mu"',
        f'mu_k = "{fmt(p["mu_ratio"])}*mu"',
    ]


def scenario_body(names, mu, force):
    """The lines of a brake scenario after its name and description: the
    run, the dofs in matrix order, the shared [params] and the [matrices]."""
    return [
        'model = "lumped"',
        "duration = 0.05",
        "sample_rate = 200000.0",
        'initial = "equilibrium"',
        "dofs = [" + ", ".join(f'"{d}"' for d in names) + "]",
        "",
        "[params]                          # shared by the pads: --param mu=0.2:1.2 moves all",
        f"mu = {fmt(mu)}",
        f"Fb = {fmt(force)}",
        "",
        "[matrices]",
        'M = "M.mtx"',
        'K = "K.mtx"',
        'C = "C.mtx"',
    ]


def add_brake_args(ap, hub_k):
    """The options every brake generator shares: the pads' caliper, the
    damping, the friction, the brake force and the sliding speed."""
    ap.add_argument("--hub-k", type=float, default=hub_k)
    ap.add_argument("--caliper-k", type=float, default=4.0e7)
    ap.add_argument("--piston-k", type=float, default=5.0e7)
    ap.add_argument("--incline", type=float, default=1.0, help="abutment angle (rad)")
    ap.add_argument("--damping-a", type=float, default=2.0)
    ap.add_argument("--damping-b", type=float, default=1.0e-8)
    ap.add_argument("--mu", type=float, default=0.45)
    ap.add_argument("--force", type=float, default=2000.0)
    ap.add_argument("--speed", type=float, default=5.0)
    ap.add_argument("--out", default=".")


def write(out, name, n_el, pads, args):
    """Write `<name>.toml` and its matrices for the given pads."""
    k, m = ring(n_el, args.radius, args.thickness, args.width, 210e9, 7850.0, args.hub_k)
    ndof_disc = 3 * n_el
    ndof = ndof_disc + 2 * len(pads)
    kk = sp.lil_matrix((ndof, ndof))
    mm = sp.lil_matrix((ndof, ndof))
    kk[:ndof_disc, :ndof_disc] = k
    mm[:ndof_disc, :ndof_disc] = m
    names = []
    for node in range(1, n_el + 1):
        names += [f"{node}_1", f"{node}_3", f"{node}_5"]
    for i, p in enumerate(pads):
        j = ndof_disc + 2 * i
        mm[j, j] = p["mass"]
        mm[j + 1, j + 1] = p["mass"]
        # The abutment holds the pad on a spring inclined by `incline` from
        # the disc's surface (it couples the pad's tangential and normal
        # motion, the mechanism of Hoffmann's minimal squeal model); the
        # piston holds the normal dof.
        ca, sa = math.cos(args.incline), math.sin(args.incline)
        kk[j, j] = p["k_caliper"] * ca * ca
        kk[j, j + 1] = kk[j + 1, j] = p["k_caliper"] * ca * sa * p["side"]
        kk[j + 1, j + 1] = p["k_caliper"] * sa * sa + p["k_piston"]
        names += [f"{p['id']}_1", f"{p['id']}_3"]
    c = args.damping_a * mm + args.damping_b * kk
    folder = os.path.join(out, name)
    os.makedirs(folder, exist_ok=True)
    for key, mat in (("M", mm), ("K", kk), ("C", c)):
        scipy.io.mmwrite(
            os.path.join(folder, f"{key}.mtx"),
            sp.coo_matrix(mat),
            symmetry="symmetric",
            precision=17,
        )
    # The same matrices in the FE packages' formats.
    write_dmig(os.path.join(folder, "brake.pch"), [("MAAX", mm), ("KAAX", kk), ("BAAX", c)], names)
    for key, suffix, mat in (("M", "MASS1", mm), ("K", "STIF1", kk), ("C", "DMPV1", c)):
        write_abaqus(os.path.join(folder, f"brake_{suffix}.mtx"), mat, names)
        write_hb_rsa(os.path.join(folder, f"brake_{key}.matrix"), mat, names, f"{name} {key} from make_brake.py")
    half = args.thickness / 2.0
    lines = [
        f"# Written by make_brake.py --elements {n_el}: a ring disc of {n_el} beam elements",
        f"# ({ndof_disc} dofs) and {len(pads)} pads ({2 * len(pads)} dofs). Do not edit: regenerate.",
        f'name = "{name}"',
        f'description = "An FE ring disc ({n_el} beam elements) with {len(pads)} pads, from Matrix Market files."',
    ] + scenario_body(names, args.mu, args.force)
    for p in pads:
        node = p["node"]
        side = p["side"]  # +1: pad on the +w face, pressing towards -w
        pid = p["id"]
        surface = f"{{ {node}_1 = 1.0, {node}_5 = {fmt(-side * half)}, {pid}_1 = -1.0 }}"
        lines += pad_toml(p, f"{node}_3", surface, args.speed)
    text = "\n".join(lines) + "\n"
    with open(os.path.join(folder, "brake.toml"), "w") as f:
        f.write(text)
    matrices = '[matrices]\nM = "M.mtx"\nK = "K.mtx"\nC = "C.mtx"\n'
    variants = {
        "dmig": '[matrices]\nM = { file = "brake.pch", name = "MAAX" }\n'
        'K = { file = "brake.pch", name = "KAAX" }\nC = { file = "brake.pch", name = "BAAX" }\n',
        "abaqus": '[matrices]\nM = "brake_MASS1.mtx"\nK = "brake_STIF1.mtx"\nC = "brake_DMPV1.mtx"\n',
        "hb": '[matrices]\nM = "brake_M.matrix"\nK = "brake_K.matrix"\nC = "brake_C.matrix"\n',
    }
    for fmt_name, m in variants.items():
        with open(os.path.join(folder, f"brake-{fmt_name}.toml"), "w") as f:
            f.write(text.replace(matrices, m).replace(f'name = "{name}"', f'name = "{name}-{fmt_name}"'))
    return ndof


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, default=40)
    ap.add_argument("--radius", type=float, default=0.15)
    ap.add_argument("--thickness", type=float, default=0.02)
    ap.add_argument("--width", type=float, default=0.05)
    add_brake_args(ap, hub_k=1.0e6)
    args = ap.parse_args()
    n = args.elements

    def pad(name, pid, node, side, k_contact, mu_ratio=1.0, share=0.5, mass=0.3, k_cal=args.caliper_k, k_pis=args.piston_k):
        return dict(
            name=name, id=pid, node=node, side=side, k_contact=k_contact,
            c_contact=0.0, mu_ratio=mu_ratio, force_share=share, mass=mass, k_caliper=k_cal, k_piston=k_pis,
        )

    a = n // 8 + 1
    two = [
        pad("inner", 9001, a, +1, 5.0e7),
        pad("outer", 9002, a, -1, 4.0e7, mu_ratio=0.9, mass=0.35, k_cal=0.75 * args.caliper_k),
    ]
    b = a + n // 2
    four = two + [
        pad("inner2", 9003, b, +1, 4.5e7, mu_ratio=1.05, share=0.45, mass=0.28),
        pad("outer2", 9004, b + 1, -1, 3.5e7, mu_ratio=0.95, share=0.45, mass=0.33, k_cal=0.875 * args.caliper_k),
    ]
    for name, pads in (("two-pad", two), ("four-pad", four)):
        ndof = write(args.out, name, n, pads, args)
        print(f"{name}: {ndof} dofs")


if __name__ == "__main__":
    main()
