"""The paper's Fig. 3a from Python: the bifurcation diagram of the cart's stroboscopic
position x(t_i), t_i = i·2π/ω, against the forcing frequency ω, swept up (red) and down
(green) with continuation, the paper's transients (100 periods first, 50 per step) and 50
recorded periods per value. Writes `paper_fig3.png`.

    python python/examples/paper_fig3.py [--quick] [OUT.png]
"""

from __future__ import annotations

import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nonsmooth as ns  # noqa: E402


def main() -> None:
    quick = "--quick" in sys.argv
    out = next((a for a in sys.argv[1:] if not a.startswith("--")), "paper_fig3.png")
    step = 0.05 if quick else 0.01
    values = 17.5 + step * np.arange(round(7.5 / step) + 1)
    cart = ns.paper(17.5)
    start = time.perf_counter()
    res = ns.sweep(cart, "omega", values, direction="both", record=50)
    print(f"{len(values)} frequencies, both directions: {time.perf_counter() - start:.1f} s")
    print("coexisting attractors (ω intervals, rad/s):",
          ", ".join(f"[{a:.2f}, {b:.2f}]" for a, b in res.hysteresis))
    fig, ax = plt.subplots(figsize=(9, 5))
    for branch, color in zip(res.branches, ("red", "green")):
        w = np.concatenate([np.full(len(p.poincare), p.param) for p in branch.points])
        x = np.concatenate([p.poincare[:, 0] for p in branch.points])
        ax.plot(w, 1e3 * x, ".", ms=1.0, color=color, label=f"sweep {branch.direction}")
    ax.axhline(1e3 * cart.parameters["x_i"], color="black", lw=0.5)
    ax.set_xlabel("ω [rad/s]")
    ax.set_ylabel("x(2πi/ω) [mm]")
    ax.set_title("The paper's cart: stroboscopic points against ω (Fig. 3a)")
    ax.legend(markerscale=8)
    fig.tight_layout()
    fig.savefig(out, dpi=150)
    print("wrote", out)


if __name__ == "__main__":
    main()
