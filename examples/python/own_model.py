"""Your own model from Python: Hoffmann's 2-dof mode-coupling brake written
as a dict (the structure of a lumped TOML file), its critical friction
coefficient, and a run above it that flutters.

    python examples/python/own_model.py          # writes docs/python-own-model.png
    python examples/python/own_model.py DIR      # or into DIR
"""

import pathlib
import sys
from typing import Any, Dict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import squeal  # noqa: E402

out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2] / "docs"

# Two masses' worth of dofs (x tangential, y normal), springs, a preload and
# a Coulomb contact with a belt: keys as in scenarios/lumped/hoffmann.toml.
model: Dict[str, Any] = {
    "name": "my-hoffmann",
    "model": "lumped",
    "duration": 5.0,
    "sample_rate": 2000.0,
    "initial": "equilibrium",
    "dofs": ["x", "y"],
    "masses": {"x": 1.0, "y": 1.0},
    "spring": [
        {"name": "kx", "on": {"x": 1.0}, "k": 8000.0, "c": 0.5},
        {"name": "ky", "on": {"y": 1.0}, "k": 0.0, "c": 0.5},
        {"name": "kxy", "on": {"x": 1.0, "y": 1.0}, "k": 2000.0, "c": 0.0},
    ],
    "force": [
        {"name": "fx", "on": {"x": 1.0}, "value": 20.0},
        {"name": "fy", "on": {"y": 1.0}, "value": 120.0},
    ],
    "contact": [
        {
            "name": "belt", "normal": {"y": 1.0}, "k": 1.0e4, "c": 0.0, "tangent": {"x": -1.0},
            "V": 1.0, "friction": "coulomb", "mu_s": 0.3, "mu_k": 0.3,
        }
    ],
    "offsets": {"y0": 1e-4},
    "solver": {"atol_pos": 1e-12, "atol_vel": 1e-10},
}

# Where steady sliding loses stability as the friction coefficient grows
# (both pad keys moved together through --set-style keywords).
crit = squeal.critical(model, param=("belt.mu_k", 0.05, 0.6))
print(f"critical friction coefficient: {crit['value']:.6f} at {crit['freq_hz']:.3f} Hz")

mu = 0.35
run = squeal.simulate(model, set={"belt.mu_s": mu, "belt.mu_k": mu})
st = squeal.stability(model, levers=False, set={"belt.mu_s": mu, "belt.mu_k": mu})
print(f"mu = {mu}: verdict {run.summary['verdict']}, growth rate {st.growth_rates.max():+.4f} 1/s")

fig, ax = plt.subplots(1, 2, figsize=(12, 4), constrained_layout=True)
ax[0].plot(run.t, run["y"], lw=0.8)
ax[0].set(xlabel="time (s)", ylabel="y (m)", title=f"μ = {mu}: {run.summary['verdict']}")
ev = st.eigenvalues
ax[1].plot(ev.real, ev.imag / (2 * np.pi), "o")
ax[1].axvline(0.0, color="k", lw=0.8)
ax[1].set(xlabel="growth rate σ (1/s)", ylabel="frequency (Hz)",
          title=f"eigenvalues; μ_c = {crit['value']:.4f}")
fig.savefig(out / "python-own-model.png", dpi=100)
