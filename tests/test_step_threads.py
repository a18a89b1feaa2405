"""The CPU step on several threads: the threads meet at a barrier, a failure never hangs, the profile adds up.

Each thread scatters into its own grid copy and the copies are summed in a fixed order, so a step on
two threads gives the same state whether it runs in one batch or in many (the barrier only orders the
stages), and a launch that fails on any thread raises in the caller instead of leaving the others waiting.
"""

import numpy as np
import pytest

import mpm_warp as mw

BLOCK = ["time.end=0.05", "time.frame_interval=0.01"]


def _block(n_threads):
    sim = mw.Simulation(mw.load_scenario("elastic_block", BLOCK), device="cpu", n_threads=n_threads)
    sim.stepper.set_frame_end(1e9)
    return sim


def test_two_threads_batches_equal_single_steps():
    """20 steps in one batch and 20 batches of one step give the same positions, bit for bit, on 2 threads."""
    a, b = _block(2), _block(2)
    assert a.stepper.n_threads == 2
    a.stepper.steps(20)
    for _ in range(20):
        b.stepper.steps(1)
    np.testing.assert_array_equal(a.state.x.numpy(), b.state.x.numpy())
    np.testing.assert_array_equal(a.state.v.numpy(), b.state.v.numpy())
    assert a.stepper.clock()[2] == 20


def test_two_threads_agree_with_one_to_round_off():
    """Two grid copies summed differ from one grid by round-off only (float32: 1e-6 m after 20 steps)."""
    a, b = _block(1), _block(2)
    a.stepper.steps(20)
    b.stepper.steps(20)
    np.testing.assert_allclose(a.state.x.numpy(), b.state.x.numpy(), atol=1e-6)


def test_a_failing_launch_on_a_worker_raises_and_the_next_steps_run():
    """A worker thread's error is raised by ``steps``, not a hang; the barrier is reset for the next batch."""
    sim = _block(2)
    st = sim.stepper
    real = st._g2p[1]

    class Broken:
        def launch(self):
            raise RuntimeError("broken launch on thread 1")

    st._g2p[1] = Broken()
    with pytest.raises(RuntimeError, match="broken launch on thread 1"):
        st.steps(3)
    st._g2p[1] = real
    steps0 = st.clock()[2]
    st.steps(2)
    assert st.clock()[2] == steps0 + 2


def test_a_failing_serial_launch_raises_without_a_hang():
    """An error in thread 0's serial launches (here an action) releases the workers waiting at the barrier."""
    sim = _block(2)
    st = sim.stepper

    class Broken:
        def launch(self):
            raise ValueError("broken action")

    st.actions.append(Broken())
    with pytest.raises(ValueError, match="broken action"):
        st.steps(2)


@pytest.mark.parametrize("n_threads", [1, 2])
def test_profile_adds_up(n_threads):
    """The profile's stages fit in the step: serial + the stage walls within the total, each thread's own work
    within its stage's wall; it advances the clock like ``steps``."""
    st = _block(n_threads).stepper
    st.steps(2)
    p = st.profile(10)
    assert p["threads"] == n_threads and p["steps"] == 10 and st.clock()[2] == 12
    walls = sum(p[s]["wall"] for s in ("p2g", "grid", "g2p"))
    assert 0.0 < p["serial"] + walls <= p["total"] * 1.0001
    for s in ("p2g", "grid", "g2p"):
        assert len(p[s]["busy"]) == n_threads
        assert 0.0 < max(p[s]["busy"]) <= p[s]["wall"] * 1.0001


def test_profile_refuses_to_time_no_op_steps():
    """Steps at the frame end do nothing (dt = 0) and time several times faster than real ones (0.3 against 1.8 ms
    a step in a 44,552-particle PST): a profile that meets the frame end raises instead of returning their times."""
    st = _block(1).stepper
    st.steps(2)
    t = st.clock()[0]
    st.set_frame_end(t)
    with pytest.raises(RuntimeError, match="frame end .* no-op steps"):
        st.profile(3)
    st.set_frame_end(t + 1.5 * st.clock()[1])      # room for about one step of three: met during the profile
    with pytest.raises(RuntimeError, match="during the profiled steps"):
        st.profile(3)
    st.set_frame_end(1e9)
    assert st.profile(3)["steps"] == 3


@pytest.mark.parametrize("spin_s", [0.0, 0.05])
def test_meeting_point_meets_many_times_and_aborts_sleepers_and_pollers(spin_s):
    """Three threads meet 200 times in order (each round's counter complete before the next); an abort then
    releases a thread that waits, sleeping or polling, with BrokenBarrierError, and reset mends it."""
    import threading

    from mpm_warp.meeting import MeetingPoint

    mp = MeetingPoint(3, spin_s=spin_s)
    mp.spin_s = spin_s   # also poll with more parties than this machine's cores
    seen = [[] for _ in range(3)]
    counter = [0] * 200
    lock = threading.Lock()

    def party(k):
        for r in range(200):
            with lock:
                counter[r] += 1
            mp.wait()
            seen[k].append(counter[r])

    threads = [threading.Thread(target=party, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=30)
    assert not any(t.is_alive() for t in threads)
    assert all(s == [3] * 200 for s in seen)
    caught = []

    def waiter():
        try:
            mp.wait()
        except threading.BrokenBarrierError:
            caught.append(True)

    t = threading.Thread(target=waiter)
    t.start()
    t.join(timeout=0.2)
    assert t.is_alive()        # alone at the meeting: it waits
    mp.abort()
    t.join(timeout=5)
    assert not t.is_alive() and caught == [True] and mp.broken
    with pytest.raises(threading.BrokenBarrierError):
        mp.wait()
    mp.reset()
    assert not mp.broken
