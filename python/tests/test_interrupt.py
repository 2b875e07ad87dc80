"""Long calls release the GIL and stop on Ctrl-C within a second with KeyboardInterrupt."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import nonsmooth as ns

LONG_RUN = textwrap.dedent(
    """
    import sys, time
    import nonsmooth as ns
    s = ns.paper(20.465)
    print("ready", flush=True)
    t = time.perf_counter()
    try:
        ns.{call}
    except KeyboardInterrupt:
        print("interrupted %.3f" % (time.perf_counter() - t), flush=True)
        sys.exit(0)
    print("finished", flush=True)
    sys.exit(1)
    """
)


def interrupt_after(call: str, delay: float = 1.0) -> float:
    """Runs `call` in a child interpreter, sends SIGINT after `delay` s, returns the time
    from the signal to the KeyboardInterrupt."""
    p = subprocess.Popen([sys.executable, "-c", LONG_RUN.format(call=call)],
                         stdout=subprocess.PIPE, text=True)
    assert p.stdout is not None
    assert p.stdout.readline().strip() == "ready"
    time.sleep(delay)
    sent = time.perf_counter()
    p.send_signal(signal.SIGINT)
    out = p.stdout.readline().strip()
    got = time.perf_counter() - sent
    assert p.wait(timeout=30) == 0, out
    assert out.startswith("interrupted"), out
    return got


def test_ctrl_c_stops_a_long_simulation() -> None:
    assert interrupt_after("simulate(s, (0.0, 1e6), max_steps=10**12)") < 1.0


def test_ctrl_c_stops_a_long_sweep() -> None:
    assert interrupt_after(
        "sweep(s, 'omega', [17.0 + 0.01 * k for k in range(600)], continuation=False, record=200)"
    ) < 1.0


def test_the_gil_is_released_during_a_run() -> None:
    ticks = 0
    stop = False

    def count() -> None:
        nonlocal ticks
        while not stop:
            ticks += 1
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    s = ns.paper(20.465)
    start = time.perf_counter()
    ns.simulate(s, (0.0, 300 * s.period))
    elapsed = time.perf_counter() - start
    stop = True
    t.join()
    # The other thread ran during the call (it would be starved if the GIL were held).
    assert ticks > 0.2 * elapsed / 0.001 * 0.1, (ticks, elapsed)


def test_progress_callback_and_interrupt_leave_no_shard(tmp_path: "os.PathLike[str]") -> None:
    import pathlib
    spec = pathlib.Path(tmp_path) / "slow.toml"
    spec.write_text(textwrap.dedent("""
        name = "slow"
        [system]
        model = "paper"
        [grid]
        x = { parameter = "omega", start = 17.5, end = 25.0, points = 256 }
        [periods]
        transient = 400
        record = 100
        """))
    # Points run in SIMD lanes, 64 per batch: progress moves batch by batch.
    calls: list[int] = []

    def progress(done: int, total: int) -> None:
        calls.append(done)
        if done >= 1:
            raise KeyboardInterrupt

    out = pathlib.Path(tmp_path) / "shards"
    try:
        ns.study.run(spec, out, progress=progress)
    except KeyboardInterrupt:
        pass
    else:
        raise AssertionError("not interrupted")
    time.sleep(8)  # the abandoned work finishes on its thread, and writes nothing
    assert calls
    assert not list(out.glob("shard-*.json"))
