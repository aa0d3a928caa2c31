"""A mode-coupling diagram and a limit cycle from Python: Hoffmann's
eigenvalues along the friction coefficient (an xarray.Dataset with units),
and the disc–pad's limit cycle with its Floquet multipliers.

    python examples/python/sweep_and_cycle.py       # writes docs/python-sweep-cycle.png
    python examples/python/sweep_and_cycle.py DIR   # or into DIR
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import squeal  # noqa: E402

out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2] / "docs"

sw = squeal.sweep("hoffmann", param=("mu", 0.0, 0.6, 61))
print("onsets:", sw.attrs["onset_value"], "coalescence:", sw.attrs["onset_coalescence"])

c = squeal.cycle("disc-pad")
mults = np.array([complex(m["re"], m["im"]) for m in c["multipliers"]])
print(f"disc-pad cycle: period {c['period']:.6e} s, largest non-trivial |μ| {c['max_multiplier']:.9f}")

fig, ax = plt.subplots(1, 3, figsize=(16, 4.4), constrained_layout=True)
for b in sw["branch"].values:
    if bool(sw["listed"][b]):
        ax[0].plot(sw["mu"], sw["freq_hz"][:, b], lw=1.2)
        ax[1].plot(sw["mu"], sw["growth_rate"][:, b], lw=1.2)
ax[0].set(xlabel=f"μ ({sw['mu'].attrs['units']})", ylabel="frequency (Hz)", title="Hoffmann: frequencies")
ax[1].axhline(0.0, color="k", lw=0.8)
ax[1].set(xlabel="μ", ylabel="growth rate σ (1/s)", title="growth rates: they split at the coalescence")
cols = c["orbit_columns"]
orbit = c["orbit"]
ax[2].plot(orbit[:, cols.index("x_p")], orbit[:, cols.index("vx_p")], lw=1.0)
ax[2].set(xlabel="x_p (m)", ylabel="vx_p (m/s)",
          title=f"disc–pad limit cycle, {1 / c['period']:.0f} Hz, |μ|max {c['max_multiplier']:.6f}")
fig.savefig(out / "python-sweep-cycle.png", dpi=100)
