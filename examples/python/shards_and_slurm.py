"""A map in shards, merged, and the same study as SLURM job scripts, from
Python: what `squeal map --shard K/N`, `squeal merge` and `squeal slurm map`
do on the command line. Each shard computes the interleaved points
i mod N = K; the merge checks that the shards belong together and writes
the unsharded map's files byte for byte.

    python examples/python/shards_and_slurm.py       # writes docs/python-shards.png
    python examples/python/shards_and_slurm.py DIR   # or into DIR
"""

import filecmp
import pathlib
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import squeal  # noqa: E402

out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2] / "docs"
X = ("V", 0.5, 20.0, 40)
Y = ("N", 100.0, 3000.0, 30)
n = 4

with tempfile.TemporaryDirectory() as tmp:
    work = pathlib.Path(tmp)
    shards = [squeal.map("disc-pad", x=X, y=Y, shard=(k, n), out=work / f"shard-{k}") for k in range(n)]
    for s in shards:
        print(f"shard {s['shard']}/{s['shards']}: {s['points']} of {s['grid_points']} points -> {s['out']}")
    ds = squeal.merge([work / f"shard-{k}" for k in range(n)], out=work / "merged")
    whole = squeal.map("disc-pad", x=X, y=Y, out=work / "whole")
    same = filecmp.cmp(work / "merged" / "map.csv", work / "whole" / "map.csv", shallow=False)
    print(f"merged map.csv equals the unsharded one byte for byte: {same}")
    assert same
    jobs = squeal.slurm("map", "disc-pad", tasks=n, x=X, y=Y, out=work / "cluster", partition="short", time="1:00:00")
    print("submit with:", jobs["submit_line"])

nx, ny = len(ds["V"]), len(ds["N"])
owner = (np.arange(nx * ny) % n).reshape(ny, nx)
fig, ax = plt.subplots(1, 2, figsize=(13, 4.6), constrained_layout=True)
ext = [float(ds["V"][0]), float(ds["V"][-1]), float(ds["N"][0]), float(ds["N"][-1])]
colours = matplotlib.colors.ListedColormap([plt.get_cmap("tab10")(k) for k in range(n)])
im0 = ax[0].imshow(owner, origin="lower", aspect="auto", extent=ext, cmap=colours, vmin=-0.5, vmax=n - 0.5)
ax[0].set(xlabel="V (m/s)", ylabel="N (N)", title=f"which of {n} shards computes each point (i mod {n})")
fig.colorbar(im0, ax=ax[0], ticks=range(n), label="shard K")
sigma = ds["max_growth_rate"]
lim = float(np.nanpercentile(np.abs(sigma.values), 98))
im1 = ax[1].imshow(sigma.values, origin="lower", aspect="auto", extent=ext, cmap="RdBu_r", vmin=-lim, vmax=lim)
ax[1].contour(ds["V"], ds["N"], sigma.values, levels=[0.0], colors="k", linewidths=1.0)
ax[1].set(xlabel="V (m/s)", ylabel="N (N)", title="merged: maximum growth rate (σ = 0 contour)")
fig.colorbar(im1, ax=ax[1], label=f"σ ({sigma.attrs['units']})")
fig.savefig(out / "python-shards.png", dpi=100)
