"""An FE brake from Python: what the files hold, its complex eigenvalues,
a Craig–Bampton reduction that can be simulated, and the squeal of the
reduced model against its eigenvalue.

    python examples/python/fe_brake.py          # writes docs/python-fe-brake.png
    python examples/python/fe_brake.py DIR      # or into DIR
"""

import pathlib
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import squeal  # noqa: E402

root = pathlib.Path(__file__).resolve().parents[2]
out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else root / "docs"
brake = root / "examples" / "fe-brake" / "two-pad" / "brake.toml"

info = squeal.inspect(brake)
print(f"{len(info['dofs'])} dofs; contacts: {', '.join(c['name'] for c in info['contacts'])}")

full = squeal.stability(brake, levers=False)
k = int(np.argmax(full.growth_rates))
print(f"full model: λ = {full.eigenvalues[k]:.4f} 1/s, {full.frequencies_hz[k]:.2f} Hz")

with tempfile.TemporaryDirectory() as tmp:
    folder = pathlib.Path(tmp) / "reduced"
    red = squeal.reduce(brake, out=folder)
    print(f"reduced to {len(red['boundary'])} boundary dofs + {len(red['generalised'])} modes")
    run = squeal.simulate(folder / "scenario.toml")
    lin = squeal.stability(folder / "scenario.toml", levers=False)

f_run = run.summary["squeal"]["frequency_hz"]
j = int(np.argmax(lin.growth_rates))
print(f"reduced model: squeal {f_run:.2f} Hz in the run, {lin.frequencies_hz[j]:.2f} Hz from its eigenvalue")

fig, ax = plt.subplots(1, 2, figsize=(12, 4), constrained_layout=True)
ax[0].plot(run.t, run["v9001_1"], lw=0.6)
ax[0].set(xlabel="time (s)", ylabel="v9001_1 (m/s)", title=f"reduced brake: {run.summary['verdict']}")
f, psd = run.spectra["v9001_1"]
ax[1].semilogy(f, psd, lw=0.8)
ax[1].axvline(lin.frequencies_hz[j], color="r", ls="--", lw=0.8, label="unstable eigenvalue")
ax[1].set(xlim=(0, 3000), xlabel="frequency (Hz)", ylabel="PSD ((m/s)²/Hz)", title="pad spectrum")
ax[1].legend()
fig.savefig(out / "python-fe-brake.png", dpi=100)
