"""Basins of attraction of the paper's cart at ω = 22.73 rad/s, where two attractors
coexist (the hysteresis the paper reports near 22.71): the study tool over the
initial-condition plane x0 × v0 (a coarser copy of
`examples/studies/paper_basin_22_73.toml`), run on every core with a progress line,
merged, and drawn with matplotlib: each point coloured by the attractor it reaches.
Writes `basin.png` (and the merged study next to it).

    python python/examples/basin.py [--quick] [OUT.png]
"""

from __future__ import annotations

import pathlib
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nonsmooth as ns  # noqa: E402

SPEC = """
name = "basin_22_73"

[system]
model = "paper"
parameters = {{ omega = 22.73 }}

[grid]
x = {{ parameter = "x0", start = -0.01, end = -0.0021, points = {n} }}
y = {{ parameter = "v0", start = -0.1, end = 0.1, points = {n} }}

[periods]
transient = {transient}
record = 60

[record]
poincare = 8
"""


def progress(done: int, total: int) -> None:
    print(f"\r{done}/{total} points", end="", file=sys.stderr, flush=True)


def main() -> None:
    quick = "--quick" in sys.argv
    out = pathlib.Path(next((a for a in sys.argv[1:] if not a.startswith("--")), "basin.png"))
    n, transient = (12, 150) if quick else (32, 300)
    with tempfile.TemporaryDirectory() as tmp:
        spec = pathlib.Path(tmp) / "basin.toml"
        spec.write_text(SPEC.format(n=n, transient=transient))
        ns.study.run(spec, pathlib.Path(tmp) / "shards", progress=progress)
        print(file=sys.stderr)
        table = ns.study.merge(pathlib.Path(tmp) / "shards", out.with_suffix(".csv"))
    for a in table.attractors:
        print(f"attractor {a.label}: {100 * a.fraction:.1f} % of the plane, period "
              f"{a.period}, {a.impacts_per_period:.3g} impacts per period")
    labels = table.grid("label")
    k = max(1, len(table.attractors))
    cmap = matplotlib.colors.ListedColormap([f"C{i}" for i in range(k)])
    fig, ax = plt.subplots(figsize=(6, 5))
    extent = (1e3 * table.x.min(), 1e3 * table.x.max(), table.y.min(), table.y.max())
    im = ax.imshow(np.ma.masked_less(labels, 0), origin="lower", extent=extent,
                   aspect="auto", cmap=cmap, vmin=-0.5, vmax=k - 0.5,
                   interpolation="nearest")
    bar = fig.colorbar(im, ax=ax, ticks=range(k))
    bar.set_ticklabels([f"{a.label}: period {a.period or '—'}" for a in table.attractors])
    ax.set_xlabel("x0 [mm]")
    ax.set_ylabel("v0 [m/s]")
    ax.set_title("Basins of the paper's cart at ω = 22.73 rad/s")
    fig.tight_layout()
    fig.savefig(out, dpi=150)
    print("wrote", out)


if __name__ == "__main__":
    main()
