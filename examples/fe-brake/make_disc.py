#!/usr/bin/env python3
"""A brake-like FE model of any size: an annular disc of 8-node hexahedra with
two pads, written as a squeal scenario with Matrix Market files.

The disc (inner radius --ri, outer --ro, thickness --h; steel) is meshed with
--radial x --circ x --layers trilinear hexahedra (full 2x2x2 Gauss
integration, consistent mass). Each node n has three translational dofs
n_1, n_2, n_3 (x, y, z; z along the axis). The hub holds every node of the
inner edge with springs of --hub-k on all three components. Like
make_brake.py, each pad is a rigid block with a tangential dof (<id>_1) on
an inclined abutment spring and a normal dof (<id>_3) on a piston spring and
pressed by the brake force; pad 9000001 touches the +z face and pad 9000002 the
-z face at the node nearest the mean radius at angle 0, where the
circumferential direction is y: the tangential sliding velocity is the
surface node's n_2 minus the pad's tangential dof.

Trilinear hexahedra lock in bending: with 2 elements through the thickness
the disc's bending frequencies are somewhat high (a few %). It is a
benchmark model with the size, sparsity and spectrum of an FE brake, not a
validated disc. Only NumPy and SciPy are used; every number written depends
only on the arguments.

    python3 make_disc.py --out /tmp/disc            # ~10^5 dofs, folder disc-<ndofs>
    python3 make_disc.py --radial 4 --circ 48 --layers 1 --out .   # a small one
"""

import argparse
import math
import os
import sys

import numpy as np
import scipy.io
import scipy.sparse as sp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_brake import add_brake_args, pad_toml, scenario_body  # noqa: E402  (the shared pad and options)

GAUSS = np.array([-1.0, 1.0]) / math.sqrt(3.0)
CORNERS = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],
    dtype=float,
)


def elasticity(e_mod, nu):
    lam = e_mod * nu / ((1 + nu) * (1 - 2 * nu))
    mu = e_mod / (2 * (1 + nu))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[np.arange(3), np.arange(3)] += 2 * mu
    d[np.arange(3, 6), np.arange(3, 6)] = mu
    return d


def hex8(xyz, e_mod, nu, rho):
    """Stiffness and consistent mass of hexahedra: xyz (E, 8, 3) -> (E, 24, 24) each."""
    n_el = xyz.shape[0]
    d = elasticity(e_mod, nu)
    ke = np.zeros((n_el, 24, 24))
    me = np.zeros((n_el, 24, 24))
    for xi in GAUSS:
        for eta in GAUSS:
            for zeta in GAUSS:
                p = np.array([xi, eta, zeta])
                shape = np.prod(1 + CORNERS * p, axis=1) / 8.0  # (8,)
                dn = np.zeros((8, 3))  # dN/dxi
                for a in range(3):
                    others = [b for b in range(3) if b != a]
                    dn[:, a] = CORNERS[:, a] * np.prod(1 + CORNERS[:, others] * p[others], axis=1) / 8.0
                jac = np.einsum("ka,ekb->eab", dn, xyz)  # (E, 3, 3): d x_b / d xi_a
                det = np.linalg.det(jac)
                dx = np.linalg.solve(jac, np.broadcast_to(dn.T, (n_el, 3, 8)))  # (E, 3, 8)
                b = np.zeros((n_el, 6, 24))
                for k in range(8):
                    c = 3 * k
                    b[:, 0, c] = dx[:, 0, k]
                    b[:, 1, c + 1] = dx[:, 1, k]
                    b[:, 2, c + 2] = dx[:, 2, k]
                    b[:, 3, c] = dx[:, 1, k]
                    b[:, 3, c + 1] = dx[:, 0, k]
                    b[:, 4, c + 1] = dx[:, 2, k]
                    b[:, 4, c + 2] = dx[:, 1, k]
                    b[:, 5, c] = dx[:, 2, k]
                    b[:, 5, c + 2] = dx[:, 0, k]
                ke += np.einsum("eij,jk,ekl,e->eil", b.transpose(0, 2, 1), d, b, det)
                nn = np.outer(shape, shape)  # (8, 8)
                m3 = np.kron(nn, np.eye(3))  # (24, 24)
                me += rho * det[:, None, None] * m3[None]
    return ke, me


def mesh(ri, ro, h, nr, nc, nz):
    """Nodes (N, 3) and hexahedra (E, 8) of the annulus."""
    r = np.linspace(ri, ro, nr + 1)
    th = 2 * math.pi * np.arange(nc) / nc
    z = np.linspace(-h / 2, h / 2, nz + 1)
    iz, ic, ir = np.meshgrid(np.arange(nz + 1), np.arange(nc), np.arange(nr + 1), indexing="ij")
    nodes = np.stack(
        [r[ir] * np.cos(th[ic]), r[ir] * np.sin(th[ic]), z[iz]], axis=-1
    ).reshape(-1, 3)

    def nid(kz, kc, kr):
        return (kz * nc + kc % nc) * (nr + 1) + kr

    ez, ec, er = np.meshgrid(np.arange(nz), np.arange(nc), np.arange(nr), indexing="ij")
    ez, ec, er = ez.ravel(), ec.ravel(), er.ravel()
    # Corners in the order of CORNERS: (xi, eta, zeta) = (radial, circumferential, axial).
    elems = np.stack(
        [
            nid(ez, ec, er), nid(ez, ec, er + 1), nid(ez, ec + 1, er + 1), nid(ez, ec + 1, er),
            nid(ez + 1, ec, er), nid(ez + 1, ec, er + 1), nid(ez + 1, ec + 1, er + 1), nid(ez + 1, ec + 1, er),
        ],
        axis=1,
    )
    return nodes, elems, nid


def assemble(nodes, elems, e_mod, nu, rho):
    ke, me = hex8(nodes[elems], e_mod, nu, rho)
    dofs = (3 * elems[:, :, None] + np.arange(3)[None, None, :]).reshape(len(elems), 24)
    rows = np.repeat(dofs, 24, axis=1).ravel()
    cols = np.tile(dofs, (1, 24)).ravel()
    n = 3 * len(nodes)
    k = sp.coo_matrix((ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    m = sp.coo_matrix((me.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    return k, m


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ri", type=float, default=0.08)
    ap.add_argument("--ro", type=float, default=0.15)
    ap.add_argument("--h", type=float, default=0.02)
    ap.add_argument("--radial", type=int, default=14)
    ap.add_argument("--circ", type=int, default=560)
    ap.add_argument("--layers", type=int, default=3)
    add_brake_args(ap, hub_k=1.0e8)
    ap.add_argument("--outer-mu-ratio", type=float, default=0.1,
                    help="the outer pad's friction coefficient as a fraction of mu (a glazed pad: the "
                    "asymmetry that makes this brake squeal; with equal pads their friction moments cancel)")
    ap.add_argument("--name", default=None)
    a = ap.parse_args()
    nodes, elems, nid = mesh(a.ri, a.ro, a.h, a.radial, a.circ, a.layers)
    k, m = assemble(nodes, elems, 210e9, 0.3, 7850.0)
    n_disc = k.shape[0]
    # Hub springs on every inner-edge node, all components.
    hub = np.array([nid(kz, kc, 0) for kz in range(a.layers + 1) for kc in range(a.circ)])
    hub_dofs = (3 * hub[:, None] + np.arange(3)).ravel()
    k = k + sp.coo_matrix((np.full(len(hub_dofs), a.hub_k), (hub_dofs, hub_dofs)), shape=k.shape)
    # Pads: rigid blocks with a tangential and a normal dof.
    ndof = n_disc + 4
    pk = sp.lil_matrix((4, 4))
    pm = sp.lil_matrix((4, 4))
    mid = int(round(a.radial / 2))
    pads = [
        dict(name="inner", id=9000001, node=nid(a.layers, 0, mid) + 1, side=+1, k_contact=5.0e7, c_contact=0.0, mu_ratio=1.0, force_share=0.5, mass=0.3, k_cal=a.caliper_k),
        dict(name="outer", id=9000002, node=nid(0, 0, mid) + 1, side=-1, k_contact=4.0e7, c_contact=0.0, mu_ratio=a.outer_mu_ratio, force_share=0.5, mass=0.35, k_cal=0.75 * a.caliper_k),
    ]
    ca, sa = math.cos(a.incline), math.sin(a.incline)
    for i, p in enumerate(pads):
        j = 2 * i
        pm[j, j] = p["mass"]
        pm[j + 1, j + 1] = p["mass"]
        pk[j, j] = p["k_cal"] * ca * ca
        pk[j, j + 1] = pk[j + 1, j] = p["k_cal"] * ca * sa * p["side"]
        pk[j + 1, j + 1] = p["k_cal"] * sa * sa + a.piston_k
    kk = sp.block_diag([k, pk])
    mm = sp.block_diag([m, pm])
    kk, mm = kk.tocsr(), mm.tocsr()
    c = a.damping_a * mm + a.damping_b * kk
    names = [f"{i}_{comp}" for i in range(1, len(nodes) + 1) for comp in (1, 2, 3)]
    for p in pads:
        names += [f"{p['id']}_1", f"{p['id']}_3"]
    name = a.name or f"disc-{ndof}"
    folder = os.path.join(a.out, name)
    os.makedirs(folder, exist_ok=True)
    for key, mat in (("M", mm), ("K", kk), ("C", c)):
        scipy.io.mmwrite(os.path.join(folder, f"{key}.mtx"), sp.coo_matrix(mat), symmetry="symmetric", precision=17)
    lines = [
        f"# Written by make_disc.py: an annular disc of {len(elems)} hexahedra ({n_disc} dofs) and 2 pads.",
        "# Do not edit: regenerate.",
        f'name = "{name}"',
        f'description = "An FE annular disc ({a.radial}x{a.circ}x{a.layers} hexahedra, {ndof} dofs) with 2 pads."',
    ] + scenario_body(names, a.mu, a.force)
    for p in pads:
        node, pid = p["node"], p["id"]
        lines += pad_toml(p, f"{node}_3", f"{{ {node}_2 = 1.0, {pid}_1 = -1.0 }}", a.speed)
    with open(os.path.join(folder, "brake.toml"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"{folder}: {ndof} dofs, K {kk.nnz} nonzeros")


if __name__ == "__main__":
    main()
