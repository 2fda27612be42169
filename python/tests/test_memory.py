"""No reference cycles and no leaks: 1000 runs keep the memory flat."""

import gc

import cdyn

SMALL = cdyn.model("pendulum", scheme="rk4", h=0.01, t_end=0.2)
PAGE = 4096


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * PAGE


def test_results_make_no_reference_cycles():
    gc.collect()
    gc.disable()
    try:
        for _ in range(50):
            r = cdyn.run(SMALL)
            cdyn.compare(SMALL)
            del r
        assert gc.collect() == 0, "results left garbage only the cycle collector could free"
    finally:
        gc.enable()


def test_memory_stays_flat_over_1000_runs():
    for _ in range(100):  # warm up: allocator pools, caches
        cdyn.run(SMALL)
    gc.collect()
    before = rss_bytes()
    for _ in range(1000):
        r = cdyn.run(SMALL)
        assert r.table.shape[0] == 21
        try:
            cdyn.run({"model": {"kind": "pendulum"}, "integrator": {"scheme": "rk4", "h": 0.0, "t_end": 1.0}})
        except cdyn.ScenarioError:
            pass
    gc.collect()
    grown = rss_bytes() - before
    # A run keeps about 21 × (8 + 2 + 2) doubles (~2 KB) and a summary; 1000
    # leaked runs would be several MB. Allow 2 MB for allocator noise.
    assert grown < 2 << 20, f"RSS grew by {grown / 1e6:.2f} MB over 1000 runs"


def test_a_run_releases_the_gil():
    """While one thread is inside a run, another runs Python code. With a
    switch interval far longer than the run, the waiting thread gets the
    GIL only if the run released it."""
    import sys
    import threading

    long_run = cdyn.model("pendulum", scheme="rk4", h=1e-4, t_end=20.0, every=1000)
    inside = threading.Event()
    done = []

    def work():
        inside.set()
        done.append(cdyn.run(long_run))

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=work)
        t.start()
        inside.wait()
        turns = 0
        while t.is_alive():
            turns += 1
            t.join(0.0005)
    finally:
        sys.setswitchinterval(interval)
    assert done and done[0].t[-1] == 20.0
    assert turns >= 10, f"the other thread ran only {turns} times during the run"


def test_ctrl_c_stops_a_run_and_raises_keyboard_interrupt():
    import os
    import signal
    import threading
    import time

    # 4·10^8 steps, minutes of work: stopped by the interrupt after 0.2 s, it
    # returns in well under the bound; ignoring it, the run would finish
    # first (and the KeyboardInterrupt come only after) in far more.
    long_run = cdyn.model("pendulum", scheme="rk4", h=1e-6, t_end=400.0, every=1000000)
    # Python's own Ctrl-C handler, whatever this process inherited: a job
    # started in the background by a non-interactive shell (`cmd &`, as a
    # CI harness may) starts with SIGINT ignored, and Python then installs
    # none, so the signal would be lost and the run go on to its end.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        cdyn.run(long_run)
        raise AssertionError("the run was not interrupted")
    except KeyboardInterrupt:
        pass
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - start < 30.0, "the run went on after Ctrl-C"
    assert cdyn.run(SMALL).error is None  # and the next run is unaffected
