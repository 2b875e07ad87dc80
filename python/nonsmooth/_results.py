"""The results of the instruments: frozen dataclasses of numpy arrays."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
C128 = npt.NDArray[np.complex128]


@dataclass(frozen=True)
class Stats:
    """Work of a run: right-hand-side evaluations, accepted and rejected steps, events."""

    rhs_evals: int
    accepted: int
    rejected: int
    events: int

    @staticmethod
    def _from(d: Any) -> "Stats":
        s = d[0]
        return Stats(int(s["rhs_evals"]), int(s["accepted"]), int(s["rejected"]), int(s["events"]))


@dataclass(frozen=True)
class ModeChange:
    """The run entered mode `mode` at time `t` (s): `"Free"`/`"Stuck"` for a rigid stop,
    `"region"`/`"sliding"` for a Filippov system."""

    t: float
    mode: str


@dataclass(frozen=True)
class Transition:
    """A Filippov transition: time, surface, kind (`crossing`, `sliding_entry`,
    `sliding_exit`, `graze`), the modes before and after, the state the next mode starts
    from."""

    t: float
    surface: int
    kind: str
    from_mode: str
    to_mode: str
    x: F64


@dataclass(frozen=True)
class Trajectory:
    """A run: dense samples `y[i]` at `t[i]`, every located event (time, surface index,
    state before and after a reset), the modes, and how the run ended.

    `stick_t`/`release_t` (rigid stops) are the times a body began to stick to the surface
    and was released; `transitions` (Filippov systems) the mode changes."""

    t: F64
    y: F64
    event_t: F64
    event_surface: npt.NDArray[np.int64]
    event_y: F64
    event_y_after: F64
    modes: list[ModeChange]
    y_final: F64
    t_final: float
    termination: str
    stats: Stats
    stick_t: F64 = field(default_factory=lambda: np.zeros(0))
    release_t: F64 = field(default_factory=lambda: np.zeros(0))
    transitions: list[Transition] = field(default_factory=list)

    @staticmethod
    def _from(d: dict[str, Any]) -> "Trajectory":
        return Trajectory(
            t=d["t"],
            y=d["y"],
            event_t=d["event_t"],
            event_surface=d["event_surface"].astype(np.int64),
            event_y=d["event_y"],
            event_y_after=d["event_y_after"],
            modes=[ModeChange(float(m["t"]), str(m["mode"])) for m in d["modes"]],
            y_final=d["y_final"],
            t_final=float(d["t_final"]),
            termination=str(d["termination"]),
            stats=Stats._from(d["stats"]),
            stick_t=d.get("stick_t", np.zeros(0)),
            release_t=d.get("release_t", np.zeros(0)),
            transitions=[
                Transition(
                    float(x["t"]), int(x["surface"]), str(x["kind"]), str(x["from"]),
                    str(x["to"]), x["x"],
                )
                for x in d.get("transitions", [])
            ],
        )


@dataclass(frozen=True)
class Impacts:
    """An impact sequence on one surface: impact times `t` (s), impact velocities (the
    rate of the penetration at contact, > 0), the intervals `T_j = t_j − t_{j−1}` (NaN for
    the first recorded impact) and the deepest penetration of each contact (NaN where not
    recorded); `count` impacts in all, `dropped` beyond the capacity."""

    t: F64
    velocity: F64
    interval: F64
    max_penetration: F64
    count: int
    dropped: int
    y_final: F64
    t_final: float
    termination: str
    stats: Stats

    @staticmethod
    def _from(d: dict[str, Any]) -> "Impacts":
        return Impacts(
            t=d["t"], velocity=d["velocity"], interval=d["interval"],
            max_penetration=d["max_penetration"], count=int(d["count"]),
            dropped=int(d["dropped"]), y_final=d["y_final"], t_final=float(d["t_final"]),
            termination=str(d["termination"]), stats=Stats._from(d["stats"]),
        )


@dataclass(frozen=True)
class Section:
    """The record of one run at one parameter value (a sweep point): the stroboscopic
    points `poincare[i] = y(t_i)`, `t_i = (transient + i + 1)·T` (one row per recorded
    forcing period `T`), the inter-impact intervals (s) and impact velocities of the
    recorded window, the impact count and impacts per forcing period, the detected period
    in forcing periods (0: none within `max_period`), the smallest per-period grazing
    margin (level − max of the contact coordinate; < 0: penetration) and the state at the
    end (phase 0)."""

    param: float
    poincare: F64
    intervals: F64
    impact_velocities: F64
    impacts: int
    impacts_per_period: float
    period: int
    grazing_margin: float
    end_state: F64

    @staticmethod
    def _from(d: dict[str, Any]) -> "Section":
        return Section(
            param=float(d["param"]), poincare=d["poincare"], intervals=d["intervals"],
            impact_velocities=d["impact_velocities"], impacts=int(d["impacts"]),
            impacts_per_period=float(d["impacts_per_period"]), period=int(d["period"]),
            grazing_margin=float(d["grazing_margin"]), end_state=d["end_state"],
        )


@dataclass(frozen=True)
class SweepTransition:
    """A parameter step along a branch where the impacts per period or the period change
    (grazing, period doubling, onset of chaos)."""

    before: float
    after: float
    impacts_before: float
    impacts_after: float
    period_before: int
    period_after: int


@dataclass(frozen=True)
class SweepBranch:
    """One direction of a sweep (`"up"` or `"down"`): its points in the order computed and
    its transitions."""

    direction: str
    points: list[Section]
    transitions: list[SweepTransition]

    @property
    def params(self) -> F64:
        """The parameter values in the order computed."""
        return np.array([p.param for p in self.points])

    @property
    def impacts_per_period(self) -> F64:
        """Impacts per forcing period at each value."""
        return np.array([p.impacts_per_period for p in self.points])

    @property
    def periods(self) -> npt.NDArray[np.int64]:
        """The detected period at each value (0: none)."""
        return np.array([p.period for p in self.points], dtype=np.int64)


@dataclass(frozen=True)
class SweepResult:
    """A sweep: the branches (one, or up then down) and the parameter intervals where the
    branches reached different attractors (`hysteresis`, pairs `(lo, hi)`)."""

    parameter: str
    branches: list[SweepBranch]
    hysteresis: list[tuple[float, float]]

    @staticmethod
    def _from(d: dict[str, Any]) -> "SweepResult":
        branches = [
            SweepBranch(
                direction=str(b["direction"]),
                points=[Section._from(p) for p in b["points"]],
                transitions=[
                    SweepTransition(
                        float(t["before"]), float(t["after"]), float(t["impacts_before"]),
                        float(t["impacts_after"]), int(t["period_before"]),
                        int(t["period_after"]),
                    )
                    for t in b["transitions"]
                ],
            )
            for b in d["branches"]
        ]
        hy = [(float(a), float(b)) for a, b in zip(d["hysteresis_lo"], d["hysteresis_hi"])]
        return SweepResult(str(d["parameter"]), branches, hy)


@dataclass(frozen=True)
class LyapunovEstimate:
    """Lyapunov exponents (1/s, largest first: one for `two_trajectory`, the state's
    dimension for `spectrum`) with the standard error of each over 10 blocks (`spread`),
    the running estimate of the top exponent after each interval (`history`), the
    renormalization interval (s) and the number of intervals."""

    exponents: F64
    spread: F64
    history: F64
    interval: float
    intervals: int
    method: str

    @property
    def top(self) -> float:
        """The largest exponent."""
        return float(self.exponents[0])

    @staticmethod
    def _from(d: dict[str, Any]) -> "LyapunovEstimate":
        return LyapunovEstimate(
            exponents=d["exponents"], spread=d["spread"], history=d["history"],
            interval=float(d["interval"]), intervals=int(d["intervals"]),
            method=str(d["method"]),
        )


@dataclass(frozen=True)
class EntropyIndex:
    """The entropy index `q* = argmax_q R(q)` of a histogram's distribution, the maximal
    redundancy `R(q*)`, the number of states (bins), whether the maximum sits at an end of
    the range searched, and the local maxima seen in the scan."""

    q: float
    redundancy: float
    states: int
    at_bound: bool
    scan_maxima: int


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit: its state at the section time, its period (s), the monodromy
    matrix `Φ = ∂P/∂y` (with saltation at impacts and sliding), the Floquet multipliers
    (eigenvalues of `Φ`, largest modulus first), the Newton iterations, the residual
    `‖P(y) − y‖∞` and whether every multiplier is inside the unit circle (for an
    autonomous system, the trivial multiplier 1 excepted)."""

    state: F64
    period: float
    monodromy: F64
    multipliers: C128
    iterations: int
    residual: float
    stable: bool

    @staticmethod
    def _from(d: dict[str, Any]) -> "PeriodicOrbit":
        return PeriodicOrbit(
            state=d["state"], period=float(d["period"]), monodromy=d["monodromy"],
            multipliers=d["multipliers"], iterations=int(d["iterations"]),
            residual=float(d["residual"]), stable=bool(d["stable"]),
        )


@dataclass(frozen=True)
class BranchPoint:
    """A point of a continued branch."""

    p: float
    arclength: float
    state: F64
    multipliers: C128
    stable: bool
    grazing_margin: Optional[float]


@dataclass(frozen=True)
class Bifurcation:
    """A located bifurcation: `fold`, `period_doubling`, `neimark_sacker` or `grazing`
    (smooth systems), `grazing_sliding`, `crossing_sliding`, `switching_sliding` or
    `adding_sliding` (Filippov systems), at parameter `p`, with the orbit's state and (for
    smooth systems) its multipliers there."""

    kind: str
    p: float
    arclength: float
    state: F64
    multipliers: C128


@dataclass(frozen=True)
class Branch:
    """A followed branch of periodic orbits: points, located bifurcations, and why it ended
    (`parameter_range`, `max_points`, `step_too_small` at `end_p`)."""

    parameter: str
    points: list[BranchPoint]
    bifurcations: list[Bifurcation]
    end: str
    end_p: Optional[float]

    @property
    def params(self) -> F64:
        """The parameter along the branch."""
        return np.array([q.p for q in self.points])

    @staticmethod
    def _from(d: dict[str, Any]) -> "Branch":
        return Branch(
            parameter=str(d["parameter"]),
            points=[
                BranchPoint(
                    float(q["p"]), float(q["arclength"]), q["state"], q["multipliers"],
                    bool(q["stable"]),
                    None if q["grazing_margin"] is None else float(q["grazing_margin"]),
                )
                for q in d["points"]
            ],
            bifurcations=[
                Bifurcation(str(b["kind"]), float(b["p"]), float(b["arclength"]), b["state"],
                            b["multipliers"])
                for b in d["bifurcations"]
            ],
            end=str(d["end"]),
            end_p=None if d["end_p"] is None else float(d["end_p"]),
        )


@dataclass(frozen=True)
class EnsembleResult:
    """Many starts of one system run together in SIMD lanes: per start its record (as
    :func:`poincare` gives it, to the bit) or the message of the error that stopped it."""

    sections: list[Optional[Section]]
    errors: list[Optional[str]]

    @property
    def end_states(self) -> F64:
        """The end state of each start (phase 0; NaN rows for failed starts)."""
        rows = [s.end_state if s is not None else None for s in self.sections]
        n = next((len(r) for r in rows if r is not None), 0)
        return np.array([r if r is not None else np.full(n, np.nan) for r in rows])

    @property
    def periods(self) -> npt.NDArray[np.int64]:
        """The detected period of each start (0: none; −1: failed)."""
        return np.array([s.period if s is not None else -1 for s in self.sections],
                        dtype=np.int64)

    @property
    def impacts_per_period(self) -> F64:
        """Impacts per forcing period of each start (NaN: failed)."""
        return np.array([s.impacts_per_period if s is not None else np.nan
                         for s in self.sections])

    @staticmethod
    def _from(d: dict[str, Any]) -> "EnsembleResult":
        sections: list[Optional[Section]] = []
        errors: list[Optional[str]] = []
        for r in d["starts"]:
            if r["status"] == "ok":
                sections.append(Section._from(r))
                errors.append(None)
            else:
                sections.append(None)
                errors.append(str(r["status"]))
        return EnsembleResult(sections, errors)


@dataclass(frozen=True)
class TimeStepRun:
    """A Moreau–Jean run: every ``every``-th step's time ``t`` (s), generalized positions
    ``q`` and velocities ``v``, energies ``(kinetic, potential, work of the impulses)``
    (J; NaN at the start); every active contact of every step as rows ``(t, contact, gap,
    ġ⁻, ġ⁺, normal impulse, tangential impulse)``; the impacts (a normal impulse with an
    approach speed above ``impact_speed``): step end time, contact, velocities before and
    after, impulse; and the run's summary."""

    t: F64
    q: F64
    v: F64
    energy: F64
    contacts: F64
    impact_t: F64
    impact_contact: npt.NDArray[np.int64]
    impact_pre: F64
    impact_post: F64
    impact_impulse: F64
    steps: int
    t_final: float
    max_residual: float
    max_active: int
    q_final: F64
    v_final: F64

    @staticmethod
    def _from(d: dict[str, Any]) -> "TimeStepRun":
        return TimeStepRun(
            t=d["t"], q=d["q"], v=d["v"], energy=d["energy"], contacts=d["contacts"],
            impact_t=d["impact_t"], impact_contact=d["impact_contact"].astype(np.int64),
            impact_pre=d["impact_pre"], impact_post=d["impact_post"],
            impact_impulse=d["impact_impulse"], steps=int(d["steps"]),
            t_final=float(d["t_final"]), max_residual=float(d["max_residual"]),
            max_active=int(d["max_active"]), q_final=d["q_final"], v_final=d["v_final"],
        )
