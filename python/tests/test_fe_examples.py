"""The FE examples' generator and the SciPy side of the large-model benchmark:
the hexahedron is a correct finite element (rigid-body modes, mass), the
generated disc has the mass of its annulus, and squeal's projected analysis
of the generated brake agrees with an independent SciPy/ARPACK analysis."""

import importlib.util
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
FE = ROOT / "examples" / "fe-brake"
CLI = os.environ.get("SQUEAL_CLI", str(ROOT / "target" / "release" / "squeal"))

scipy = pytest.importorskip("scipy")


def make_disc():
    spec = importlib.util.spec_from_file_location("make_disc", FE / "make_disc.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_one_hexahedron_has_six_rigid_body_modes_and_its_mass():
    md = make_disc()
    cube = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [0, 0, 3], [2, 0, 3], [2, 1, 3], [0, 1, 3]], float)
    k, m = md.hex8(cube[None], 210e9, 0.3, 7850.0)
    k, m = k[0], m[0]
    assert np.allclose(k, k.T, rtol=0, atol=1e-6 * abs(k).max())
    w = np.linalg.eigvalsh(k)
    assert np.sum(np.abs(w) < 1e-9 * w.max()) == 6
    assert w[6] > 1e-4 * w.max()
    # The consistent mass of each direction sums to rho * volume (6 m^3).
    for d in range(3):
        assert m[d::3, d::3].sum() == pytest.approx(7850.0 * 6.0, rel=1e-12)


def test_the_disc_has_the_mass_of_its_annulus(tmp_path):
    md = make_disc()
    nodes, elems, _ = md.mesh(0.08, 0.15, 0.02, 3, 24, 2)
    _, m = md.assemble(nodes, elems, 210e9, 0.3, 7850.0)
    # Straight-sided elements: the annulus of a 24-gon.
    area = 24 / 2 * math.sin(2 * math.pi / 24) * (0.15**2 - 0.08**2)
    ex = np.zeros(m.shape[0])
    ex[0::3] = 1.0
    assert ex @ (m @ ex) == pytest.approx(7850.0 * area * 0.02, rel=1e-12)


def test_squeal_and_scipy_agree_on_the_generated_brake(tmp_path):
    subprocess.run(
        [sys.executable, str(FE / "make_disc.py"), "--radial", "3", "--circ", "24", "--layers", "1",
         "--name", "tiny", "--out", str(tmp_path)],
        check=True, capture_output=True,
    )
    sc = tmp_path / "tiny" / "brake.toml"
    text = sc.read_text()
    import tomllib
    dofs = tomllib.loads(text)["dofs"]
    assert len(dofs) == 3 * 4 * 24 * 2 + 4 == 580
    ours = json.loads(subprocess.run(
        [CLI, "stability", str(sc), "--no-levers", "--json", "--set", "modal.dense_max_dofs=0",
         "--set", "modal.cutoff_hz=20000"],
        check=True, capture_output=True, text=True).stdout)
    theirs = json.loads(subprocess.run(
        [sys.executable, str(FE / "scipy_cea.py"), str(sc), "--cutoff-hz", "20000"],
        check=True, capture_output=True, text=True).stdout)
    assert ours["modal"]["modes"] == theirs["modes"]
    grow = [e for e in ours["eigenvalues"] if e["growing"] and e["im"] >= 0]
    assert len(grow) == len(theirs["unstable"]) >= 1
    for a, b in zip(grow, theirs["unstable"]):
        assert complex(a["re"], a["im"]) == pytest.approx(complex(b["re"], b["im"]), rel=1e-9)
