"""A tour of `import squeal`: the stability map of V × N, the default run's
pad spectrum, and one transient point — in one figure.

Run it as is from the repository (after `pip install ./python matplotlib`):

    python examples/python/squeal_tour.py            # writes docs/python-tour.png
    python examples/python/squeal_tour.py out.png    # or anywhere else (a folder: its python-tour.png)
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import squeal  # noqa: E402

out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2] / "docs" / "python-tour.png"
if out.is_dir():
    out = out / "python-tour.png"

# 1. Linear stability of steady sliding over sliding speed V × normal load N
#    (parallel, deterministic; an xarray.Dataset when xarray is installed).
m = squeal.map("disc-pad", x=("V", 0.5, 20.0, 60), y=("N", 100.0, 3000.0, 45))
V, N = np.asarray(m["V"]), np.asarray(m["N"])
sigma = np.asarray(m["max_growth_rate"])

# 2. The default run and its pad spectrum (the Welch spectrum behind summary.json).
run = squeal.simulate("disc-pad")
f, psd = run.spectra["vx_p"]

# 3. One transient point: a fast, lightly loaded brake, where the map says it squeals.
point = dict(V=12.0, N=600.0)
st = squeal.stability("disc-pad", levers=False, V=point["V"], N=point["N"])
tr = squeal.simulate("disc-pad", duration=0.5, V=point["V"], N=point["N"])

fig, ax = plt.subplots(1, 3, figsize=(16, 4.6), constrained_layout=True)
lim = np.nanpercentile(np.abs(sigma), 98)
pc = ax[0].pcolormesh(V, N, sigma, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest")
ax[0].contour(V, N, sigma, levels=[0.0], colors="k", linewidths=1.2)
ax[0].plot(point["V"], point["N"], "k*", ms=12)
fig.colorbar(pc, ax=ax[0], label="max growth rate σ (1/s)")
ax[0].set(xlabel="V (m/s)", ylabel="N (N)", title="stability of steady sliding (σ > 0: squeal)")

ax[1].semilogy(f, psd, lw=0.9)
ax[1].set(xlim=(0, 30000), xlabel="frequency (Hz)", ylabel="PSD of vx_p ((m/s)²/Hz)",
          title=f"default run: pad spectrum, verdict {run.summary['verdict']}")

ax[2].plot(tr.t, tr["vx_p"], lw=0.6)
ax[2].set(xlabel="t (s)", ylabel="vx_p (m/s)",
          title=f"V = {point['V']} m/s, N = {point['N']:.0f} N: σ = {st.growth_rates[0]:+.1f} 1/s, "
                f"{st.least_stable['freq_hz']:.0f} Hz")
fig.savefig(out, dpi=110)
print(f"{out}: map {sigma.shape}, {np.sum(sigma > 0)} unstable points; run verdict {run.summary['verdict']}; "
      f"transient point verdict {tr.summary['verdict']}")
