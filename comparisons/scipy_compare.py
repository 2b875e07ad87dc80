#!/usr/bin/env python3
"""The same work-precision measurements as the Rust binary, with SciPy's solve_ivp.

Workloads (the paper's oscillator at omega = 20.465 rad/s; see README.md):
  W1  1100 forcing periods from rest at the static equilibrium,
  W2  1000 periods from the state reached after 100 periods,
  accuracy: x after 10 periods from states on the attractor (worst of the brief's 5, and the
  RMS over the 10 section times of 40 runs) and the worst impact-time error over those periods,
  against the Rust binary's reference (results/reference_*.csv: run `cargo run --release`
  first).

Methods: RK45, DOP853, LSODA, Radau (analytic Jacobian for the implicit ones); impacts are
`events` with direction=+1 (g = x - x_I), sections are `t_eval` at t0 + i*2*pi/omega.
Tolerances: rtol and atol = [rtol*1e-4, rtol*1e-2] (x in m, v in m/s), as for the Rust peers.
Times are CPU seconds (time.process_time) per 1000 periods, median of --reps runs; a run
that exceeds --budget CPU seconds is stopped by a terminal event and its time extrapolated
(marked ~).

Usage: python3 scipy_compare.py [--reps 3] [--budget 30] [--rtols 1e-6,1e-8,1e-10]
                                [--methods RK45,DOP853,LSODA,Radau] [--tables-only]
(--tables-only redoes results/scipy.md from results/scipy.csv and results/table.csv.)
Exits 0 with a message if SciPy is not installed.
"""

import argparse
import csv
import math
import os
import sys
import time

try:
    import numpy as np
    import scipy
    from scipy.integrate import solve_ivp
except ImportError:  # pragma: no cover - environment dependent
    print("scipy_compare.py: SciPy/NumPy not installed (pip install scipy numpy); skipping.")
    sys.exit(0)

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")

# The paper's parameters (nonsmooth::systems::paper::PAPER).
# err x10 is the worst end error over the brief's 5 fixed starts (forcing periods); the RMS
# and the impact errors use every start of the reference (40, see README.md).
BRIEF_STARTS = (100, 120, 140, 160, 180)
M, M0E, K, C, T_FR, EPS = 8.735, 0.01805, 1418.9, 6.6511, 0.63133, 1e-6
K_I, B, N3, X_I, ETA = 2.3983e8, 0.8485, 0.18667, -2.086e-3, 1e-8
HALF_N3_M1 = (N3 - 1.0) * 0.5
MATCH_WINDOW = 1e-3


def make_rhs(omega):
    amp = M0E * omega * omega
    inv_m = 1.0 / M
    sqrt, exp, log, sin = math.sqrt, math.exp, math.log, math.sin
    counter = [0]

    def rhs(t, y):
        counter[0] += 1
        x, v = y[0], y[1]
        fric = T_FR * v / sqrt(v * v + EPS * EPS)
        d = x - X_I
        contact = 0.0
        if d > 0.0:
            p1 = d * sqrt(d)
            p = exp(HALF_N3_M1 * log(v * v + ETA * ETA))
            f = p1 + B * p1 * (v * p)
            if f > 0.0:
                contact = K_I * f
        total = K * x + C * v + fric + contact
        return (v, (amp * sin(omega * t) - total) * inv_m)

    def jac(t, y):
        x, v = y[0], y[1]
        e2 = EPS * EPS
        s = v * v + e2
        fx = K
        fv = C + T_FR * e2 / (s * sqrt(s))
        d = x - X_I
        if d > 0.0:
            sd = sqrt(d)
            p1, dp1 = d * sd, 1.5 * sd
            s2 = v * v + ETA * ETA
            p = exp(HALF_N3_M1 * log(s2))
            g = v * p
            dg = p * (N3 * v * v + ETA * ETA) / s2
            if p1 + B * p1 * g > 0.0:
                fx += K_I * (dp1 + B * dp1 * g)
                fv += K_I * (B * p1 * dg)
        return np.array([[0.0, 1.0], [-fx * inv_m, -fv * inv_m]])

    return rhs, jac, counter


def impact_event(t, y):
    return y[0] - X_I


impact_event.direction = 1.0
impact_event.terminal = False


def budget_event(limit):
    """A terminal event that fires once `limit` CPU seconds are spent: g = t_stop - t with
    t_stop = +inf until then, and just below the current time afterwards (deterministic in t,
    so SciPy's root polish on it is well defined)."""
    start = time.process_time()
    state = {"calls": 0, "t_stop": math.inf}

    def ev(t, y):
        state["calls"] += 1
        if state["t_stop"] == math.inf and state["calls"] % 64 == 0 \
                and time.process_time() - start > limit:
            state["t_stop"] = t - 1e-12 * max(1.0, abs(t))
        return 1.0 if state["t_stop"] == math.inf else state["t_stop"] - t

    ev.terminal = True
    ev.direction = -1.0
    return ev


def run(method, omega, t0, y0, n_periods, rtol, budget):
    """Returns dict(status, cpu, frac, nfev, impacts, t_end, x_end)."""
    period = 2.0 * math.pi / omega
    t_end = t0 + n_periods * period
    t_eval = t0 + period * np.arange(1, n_periods + 1)
    t_eval[-1] = t_end
    rhs, jac, counter = make_rhs(omega)
    kw = {}
    if method in ("Radau", "BDF", "LSODA"):
        kw["jac"] = jac
    c0 = time.process_time()
    try:
        sol = solve_ivp(
            rhs, (t0, t_end), list(y0), method=method, t_eval=t_eval,
            events=[impact_event, budget_event(budget)], rtol=rtol,
            atol=[rtol * 1e-4, rtol * 1e-2], **kw)
    except Exception as e:  # noqa: BLE001 - report any solver failure
        return dict(status=f"failed: {e}", cpu=time.process_time() - c0, frac=0.0,
                    nfev=counter[0], impacts=[], x_end=float("nan"), xs=[])
    cpu = time.process_time() - c0
    t_reached = sol.t[-1] if len(sol.t) else t0
    if sol.t_events[1].size:
        t_reached = sol.t_events[1][0]
    frac = max(0.0, min(1.0, (t_reached - t0) / (t_end - t0)))
    if sol.status == 1:
        status = f"timeout at {100 * frac:.1f}%"
    elif sol.status != 0:
        status = f"failed at {100 * frac:.1f}%: {sol.message}"
    else:
        status = "ok"
    x_end = sol.y[0][-1] if status == "ok" and len(sol.t) and sol.t[-1] == t_end else float("nan")
    xs = list(sol.y[0]) if status == "ok" else []
    return dict(status=status, cpu=cpu, frac=frac, nfev=counter[0],
                impacts=list(sol.t_events[0]), x_end=x_end, xs=xs)


def impact_errors(ref, got):
    worst, missed = 0.0, 0
    for r in ref:
        d = min((abs(g - r) for g in got), default=math.inf)
        if d <= MATCH_WINDOW:
            worst = max(worst, d)
        else:
            missed += 1
    extra = sum(1 for g in got if all(abs(g - r) > MATCH_WINDOW for r in ref))
    return worst, missed, extra


def timing(method, omega, t0, y0, n, rtol, budget, reps):
    times, last = [], None
    for _ in range(max(1, reps)):
        r = run(method, omega, t0, y0, n, rtol, budget)
        periods = (1.0 if r["status"] == "ok" else r["frac"]) * n
        times.append(r["cpu"] / periods * 1000.0 if periods > 0 else float("nan"))
        last = (r, periods)
        if r["status"] != "ok":
            break
    r, periods = last
    times.sort()
    return dict(s=times[len(times) // 2], reps=len(times), status=r["status"],
                rhs=r["nfev"] / periods if periods > 0 else float("nan"),
                impacts=len(r["impacts"]))


def read_reference():
    def rows(name):
        with open(os.path.join(RESULTS, name), newline="") as f:
            return list(csv.DictReader(f))

    setup = rows("reference_setup.csv")[0]
    states = rows("reference_states.csv")
    imps = rows("reference_impacts.csv")
    secs = rows("reference_sections.csv")
    segs = []
    for s in states:
        k = int(s["k"])
        segs.append(dict(t0=float(s["t0_s"]), y0=(float(s["x0_m"]), float(s["v0_m_s"])),
                         brief=int(s["start_period"]) in BRIEF_STARTS,
                         x_end=float(s["x_end_m"]),
                         impacts=[float(i["t_s"]) for i in imps if int(i["k"]) == k],
                         xs=[float(q["x_m"]) for q in secs if int(q["k"]) == k]))
    return setup, segs


def time_at_error(points, e):
    """log-log interpolation of time at error e; (time, how) or None."""
    p = sorted((math.log(err), math.log(t)) for err, t in points
               if err > 0 and t > 0 and math.isfinite(err) and math.isfinite(t))
    if not p or not e > 0:
        return None
    le = math.log(e)

    def lerp(a, b):
        if abs(b[0] - a[0]) < 1e-12:
            return 0.5 * (a[1] + b[1])
        return a[1] + (b[1] - a[1]) * (le - a[0]) / (b[0] - a[0])

    if len(p) == 1:
        return (math.exp(p[0][1]), "=") if abs(le - p[0][0]) < 0.05 else None
    for a, b in zip(p, p[1:]):
        if a[0] <= le <= b[0]:
            return math.exp(lerp(a, b)), ""
    if le < p[0][0] and p[0][0] - le <= math.log(10):
        return math.exp(lerp(p[0], p[1])), "*"
    if le > p[-1][0] and le - p[-1][0] <= math.log(10):
        return math.exp(lerp(p[-2], p[-1])), "*"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--budget", type=float, default=30.0)
    ap.add_argument("--rtols", default="1e-6,1e-8,1e-10")
    ap.add_argument("--methods", default="RK45,DOP853,LSODA,Radau")
    ap.add_argument("--tables-only", action="store_true",
                    help="redo scipy.md from results/scipy.csv and results/table.csv")
    a = ap.parse_args()
    if a.tables_only:
        rows, version = rows_from_csv()
        write_outputs(rows, version)
        return 0
    try:
        setup, segs = read_reference()
    except FileNotFoundError:
        print("scipy_compare.py: results/reference_*.csv missing: run `cargo run --release` first.")
        return 1
    omega = float(setup["omega_rad_s"])
    period = 2 * math.pi / omega
    x_rest = float(setup["x_rest_m"])
    w2_t0 = int(setup["w2_start_period"]) * period
    w2_y0 = (float(setup["w2_x0_m"]), float(setup["w2_v0_m_s"]))
    n1, n2, nacc = int(setup["w1_periods"]), int(setup["w2_periods"]), int(setup["acc_periods"])
    print(f"SciPy {scipy.__version__}, NumPy {np.__version__}; omega = {omega} rad/s; "
          f"reference impacts W1 {setup['w1_ref_impacts']}, W2 {setup['w2_ref_impacts']}")
    rows = []
    for rtol in [float(r) for r in a.rtols.split(",")]:
        for method in a.methods.split(","):
            err_x, err_t, missed, extra, acc_status = 0.0, 0.0, 0, 0, "ok"
            sq, nsq = 0.0, 0
            for s in segs:
                r = run(method, omega, s["t0"], s["y0"], nacc, rtol, a.budget)
                if r["status"] != "ok":
                    acc_status, err_x = r["status"], float("nan")
                    break
                if s["brief"]:
                    err_x = max(err_x, abs(r["x_end"] - s["x_end"]))
                if len(r["xs"]) == len(s["xs"]):
                    sq += sum((a - b) ** 2 for a, b in zip(r["xs"], s["xs"]))
                    nsq += len(s["xs"])
                else:
                    nsq = -10**9
                w, mi, ex = impact_errors(s["impacts"], r["impacts"])
                err_t, missed, extra = max(err_t, w), missed + mi, extra + ex
            w2 = timing(method, omega, w2_t0, w2_y0, n2, rtol, a.budget, a.reps)
            w1 = timing(method, omega, 0.0, (x_rest, 0.0), n1, rtol, a.budget, a.reps)
            err_rms = math.sqrt(sq / nsq) if acc_status == "ok" and nsq > 0 else float("nan")
            row = dict(method=method, rtol=rtol, w1=w1, w2=w2, err_x=err_x, err_rms=err_rms,
                       err_t=err_t,
                       missed=missed, extra=extra, acc_status=acc_status)
            rows.append(row)

            def f(t):
                return ("" if t["status"] == "ok" else "~") + f"{t['s']:.3f}"
            notes = "; ".join(f"{n}: {st}" for n, st in
                              (("acc", acc_status), ("W1", w1["status"]), ("W2", w2["status"]))
                              if st != "ok")
            print(f"scipy {method:<7} rtol {rtol:.0e}: W1 {f(w1):>9} W2 {f(w2):>9} s/1000P, "
                  f"{w2['rhs']:8.0f} RHS/P, impacts {w1['impacts']}/{w2['impacts']}, "
                  f"err x10 {err_x:.1e}, rms {err_rms:.1e}, dt {err_t:.1e}, "
                  f"missed/extra {missed}/{extra} {notes}",
                  flush=True)

    write_outputs(rows, scipy.__version__)
    return 0


def rows_from_csv():
    """The rows of a previous run (results/scipy.csv), to redo the tables only."""
    def num(x):
        return float(x) if x not in ("", "nan") else float("nan")
    rows = []
    with open(os.path.join(RESULTS, "scipy.csv"), newline="") as f:
        for r in csv.DictReader(f):
            rows.append(dict(
                method=r["method"], rtol=num(r["rtol"]),
                w1=dict(s=num(r["w1_s_per_1000_periods"]), status=r["w1_status"],
                        impacts=int(r["w1_impacts"]), rhs=float("nan")),
                w2=dict(s=num(r["w2_s_per_1000_periods"]), status=r["w2_status"],
                        impacts=int(r["w2_impacts"]), rhs=num(r["w2_rhs_per_period"])),
                err_x=num(r["err_x_m"]), err_rms=num(r["err_x_rms_m"]),
                err_t=num(r["err_t_impact_s"]), missed=int(r["missed_impacts"]),
                extra=int(r["extra_impacts"]), acc_status=r["accuracy_status"]))
    version = r["library"].split()[-1] if rows else "?"
    return rows, version


def usable(status):
    """Points that enter the equal-accuracy interpolation: finished runs, and runs stopped by
    the budget (their per-period time is extrapolated from the part done; W2 is stationary)."""
    return status == "ok" or status.startswith("timeout")


def write_outputs(rows, version):
    # Output: CSV + markdown, with our time / SciPy time at equal accuracy.
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "scipy.csv"), "w", newline="") as fcsv:
        w = csv.writer(fcsv)
        w.writerow(["library", "method", "rtol", "w1_s_per_1000_periods", "w1_status",
                    "w2_s_per_1000_periods", "w2_status", "w2_rhs_per_period", "w1_impacts",
                    "w2_impacts", "err_x_m", "err_x_rms_m", "err_t_impact_s", "missed_impacts",
                    "extra_impacts", "accuracy_status"])
        for r in rows:
            w.writerow([f"scipy {version}", r["method"], r["rtol"], r["w1"]["s"],
                        r["w1"]["status"], r["w2"]["s"], r["w2"]["status"], r["w2"]["rhs"],
                        r["w1"]["impacts"], r["w2"]["impacts"], r["err_x"], r["err_rms"],
                        r["err_t"],
                        r["missed"], r["extra"], r["acc_status"]])
    md = ["# SciPy solve_ivp on the same workloads", "",
          f"SciPy {version}. CPU seconds per 1000 periods (`~`: extrapolated from "
          "the part done before the budget ran out).", "",
          "| method | rtol | W1 s/1000P | W2 s/1000P | RHS/period | impacts W1 | impacts W2 "
          "| err x₁₀ (m) | RMS err x (m) | Δt impact (s) | missed/extra | notes |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        notes = "; ".join(f"{n}: {st}" for n, st in (("acc", r["acc_status"]),
                                                      ("W1", r["w1"]["status"]),
                                                      ("W2", r["w2"]["status"])) if st != "ok")

        def f(t):
            return ("" if t["status"] == "ok" else "~") + f"{t['s']:.3f}"
        md.append(f"| {r['method']} | {r['rtol']:.0e} | {f(r['w1'])} | {f(r['w2'])} | "
                  f"{r['w2']['rhs']:.0f} | {r['w1']['impacts']} | {r['w2']['impacts']} | "
                  f"{r['err_x']:.1e} | {r['err_rms']:.1e} | {r['err_t']:.1e} | "
                  f"{r['missed']}/{r['extra']} | {notes} |")
    ours_path = os.path.join(RESULTS, "table.csv")
    if os.path.exists(ours_path):
        with open(ours_path, newline="") as fo:
            ours = [o for o in csv.DictReader(fo) if o["library"] == "nonsmooth"
                    and o["method"] in ("Dopri5", "Dop853")]
        methods = list(dict.fromkeys(r["method"] for r in rows))
        for wl in ("w2", "w1"):
            md += ["", f"Our time / SciPy time at equal RMS x error ({wl.upper()}; log-log "
                   "interpolation, `*` extrapolated by at most one decade of error; runs "
                   "stopped by the budget enter with their extrapolated time):", "",
                   "| nonsmooth | rtol | RMS err x | s/1000P | " + " | ".join(methods) + " |",
                   "|---|---|---|---|" + "---|" * len(methods)]
            for o in ours:
                try:
                    oe, ot = float(o["err_x_rms_m"]), float(o[f"{wl}_s_per_1000_periods"])
                except ValueError:
                    continue
                if not (math.isfinite(oe) and math.isfinite(ot)) or o[f"{wl}_status"] != "ok":
                    continue
                cells = []
                for m in methods:
                    pts = [(r["err_rms"], r[wl]["s"]) for r in rows
                           if r["method"] == m and usable(r[wl]["status"])]
                    ti = time_at_error(pts, oe)
                    cells.append("—" if ti is None else f"{ot / ti[0]:.3f}{ti[1]}")
                md.append(f"| {o['method']} | {float(o['rtol']):.0e} | {oe:.1e} | {ot:.3f} | "
                          + " | ".join(cells) + " |")
    text = "\n".join(md) + "\n"
    with open(os.path.join(RESULTS, "scipy.md"), "w") as fmd:
        fmd.write(text)
    print()
    print(text)


if __name__ == "__main__":
    sys.exit(main())
