"""State: save, restore and branch reruns are bit-identical; copies and pickles too."""
import copy
import pickle

import numpy as np
import pytest

from conftest import C60_PROBE, scene


def c60(nscd_sim):
    return nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=C60_PROBE)


def test_restore_and_rerun_is_bit_identical(nscd_sim):
    sim = c60(nscd_sim)
    sim.step(80)  # past the first settling steps: warm starts and ring hints are set
    saved = sim.state()
    first = sim.run(0.0004, include_start=False)
    end_first = sim.state()
    sim.set_state(saved)
    assert sim.steps == 80 and sim.time == saved.t
    again = sim.run(0.0004, include_start=False)
    assert again.tobytes() == first.tobytes()
    assert sim.state() == end_first


def test_branch_in_a_second_simulator_is_bit_identical(nscd_sim):
    """A State moves to another Simulator of the same scene, even through pickle, and
    both continue alike; a branch with another command diverges from it."""
    a = c60(nscd_sim)
    a.step(90)
    saved = pickle.loads(pickle.dumps(a.state()))
    b = c60(nscd_sim)
    b.set_state(saved)
    ra, rb = a.run(0.0003), b.run(0.0003)
    assert ra[1:].tobytes() == rb[1:].tobytes()  # the start record: b's last-step outputs were cleared
    assert a.state() == b.state()
    c = nscd_sim.Simulator(scene('urdf/c60.urdf'), commands='probe=0:0,0.0007:0,0.0207:0.008')
    c.set_state(saved)
    rc = c.run(0.0003)
    assert not np.array_equal(rc['probe.cmd'], ra['probe.cmd'])


def test_reset_reruns_from_the_start(nscd_sim):
    sim = nscd_sim.Simulator(scene('urdf/clearance_pendulum.urdf'))
    first = sim.run(0.005)
    sim.reset()
    assert sim.time == 0 and sim.steps == 0
    assert sim.run(0.005).tobytes() == first.tobytes()


def test_state_pickle_and_copy_round_trip(nscd_sim):
    sim = c60(nscd_sim)
    sim.step(50)
    s = sim.state()
    for other in (pickle.loads(pickle.dumps(s)), pickle.loads(pickle.dumps(s, protocol=2)), copy.copy(s),
                  copy.deepcopy(s), s.copy()):
        assert other == s
        assert other.bodies.tobytes() == s.bodies.tobytes()
        assert other.t == s.t
    assert s.bodies.shape == (len(sim.body_names), 13)
    sim.step()
    assert sim.state() != s  # == can fail


def test_state_is_a_copy(nscd_sim):
    sim = nscd_sim.Simulator(scene('urdf/ball.urdf'))
    s = sim.state()
    sim.step(10)
    assert s.t == 0 and sim.state().t > 0
    with pytest.raises(TypeError):
        hash(s)


def test_simulators_in_parallel_threads_match_serial_runs(nscd_sim):
    """With the GIL released, two Simulators step at once; they share nothing, so each
    gives its serial run's records."""
    import threading
    kwargs = [dict(commands=C60_PROBE), dict(commands=C60_PROBE, settings={'tolerance': 1e-6})]
    serial = [nscd_sim.Simulator(scene('urdf/c60.urdf'), **k).run(0.002, every=20) for k in kwargs]
    sims = [nscd_sim.Simulator(scene('urdf/c60.urdf'), **k) for k in kwargs]
    out = [None, None]

    def work(i):
        out[i] = sims[i].run(0.002, every=20)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert out[0].tobytes() == serial[0].tobytes() and out[1].tobytes() == serial[1].tobytes()
    assert out[0].tobytes() != out[1].tobytes()
