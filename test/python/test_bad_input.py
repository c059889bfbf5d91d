"""Every class of bad input raises a Python exception with a clear message, never crashes."""
import glob
import math
import os
import pickle
import threading
import time

import numpy as np
import pytest

from conftest import C60_PROBE, REPO, run_cli, scene

BAD_SCENES = sorted(glob.glob(os.path.join(REPO, 'test', 'scenes', 'bad', '*.urdf')))


def test_there_are_bad_scenes():
    assert len(BAD_SCENES) >= 20


@pytest.mark.parametrize('path', BAD_SCENES, ids=os.path.basename)
def test_bad_scene_raises_scene_error_with_the_cli_line(nscd_sim, tmp_path, path):
    status, stderr, _ = run_cli([path, '--duration', '0.001'], tmp_path)
    assert status == 2
    with pytest.raises(nscd_sim.SceneError) as e:
        nscd_sim.Simulator(path)
    assert str(e.value) == stderr.strip()
    assert str(e.value).startswith(path)
    assert isinstance(e.value, ValueError)


@pytest.mark.parametrize('yaml', ['bad_settings.yaml', 'malformed.yaml'])
def test_bad_config_raises_scene_error_with_the_cli_line(nscd_sim, tmp_path, yaml):
    config = scene('test', 'scenes', 'bad', yaml)
    status, stderr, _ = run_cli([scene('urdf/ball.urdf'), '--config', config, '--duration', '0'], tmp_path)
    assert status == 2
    with pytest.raises(nscd_sim.SceneError) as e:
        nscd_sim.Simulator(scene('urdf/ball.urdf'), config=config)
    assert str(e.value) == stderr.strip()


def test_missing_scene_file(nscd_sim):
    with pytest.raises(nscd_sim.SceneError, match='no_such_scene.urdf'):
        nscd_sim.Simulator('/no/such/dir/no_such_scene.urdf')


def test_scene_error_pickles(nscd_sim):
    with pytest.raises(nscd_sim.SceneError) as e:
        nscd_sim.Simulator('/no/such/scene.urdf')
    again = pickle.loads(pickle.dumps(e.value))
    assert type(again) is nscd_sim.SceneError and str(again) == str(e.value)


@pytest.mark.parametrize('settings, message', [
    ({'time_step': 1e-4}, "unknown setting 'time_step'"),
    ({'dt': 0}, 'dt'),
    ({'dt': float('nan')}, 'dt'),
    ({'theta': 0.2}, 'theta'),
    ({'tolerance': -1}, 'tolerance'),
    (['projection=maybe'], 'projection'),
])
def test_bad_setting_raises_scene_error(nscd_sim, settings, message):
    with pytest.raises(nscd_sim.SceneError, match=message) as e:
        nscd_sim.Simulator(scene('urdf/ball.urdf'), settings=settings)
    assert str(e.value).startswith('settings')


@pytest.mark.parametrize('settings, error', [
    ('dt=1e-4', TypeError),            # one string, not a list of them
    ({'dt': object()}, TypeError),
    ({1: 2}, TypeError),
    (['dt'], ValueError),              # no '='
])
def test_malformed_settings_argument(nscd_sim, settings, error):
    with pytest.raises(error, match='settings'):
        nscd_sim.Simulator(scene('urdf/ball.urdf'), settings=settings)


@pytest.mark.parametrize('commands, message', [
    ('nozzle=0:0', "no actuator 'nozzle' \\(actuators: handle, probe, bar_seating\\)"),
    ({'nozzle': '0:0'}, "no actuator 'nozzle'"),
    ('probe=0:0,0.001:nan', 'not a finite number'),
    ('probe=0.002:0,0.001:1', 'times must not decrease'),
    ('probe', 'expected NAME=t0:v0'),
    ([C60_PROBE, C60_PROBE], "two schedules for actuator 'probe'"),
    ({'probe': [(0, 0), (0.001, float('inf'))]}, 'not a finite number'),
])
def test_bad_command_schedule_raises_value_error(nscd_sim, commands, message):
    with pytest.raises(ValueError, match='commands: .*' + message):
        nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=commands)


def test_schedule_pairs_must_be_pairs(nscd_sim):
    with pytest.raises(TypeError, match='pairs'):
        nscd_sim.Simulator(scene('urdf/c60.urdf'), commands={'probe': [(0, 0, 1)]})
    with pytest.raises(TypeError, match='number'):
        nscd_sim.Simulator(scene('urdf/c60.urdf'), commands={'probe': [('a', 0)]})


@pytest.fixture
def pendulum(nscd_sim):
    return nscd_sim.Simulator(scene('urdf/clearance_pendulum.urdf'))


@pytest.mark.parametrize('duration', [-1e-3, float('nan'), float('inf'), 1e30])
def test_bad_duration(pendulum, duration):
    with pytest.raises(ValueError, match='duration'):
        pendulum.run(duration)
    assert pendulum.steps == 0


def test_bad_step_counts(pendulum):
    with pytest.raises(ValueError, match='every'):
        pendulum.run(0.001, every=0)
    with pytest.raises(ValueError, match='>= 0'):
        pendulum.step(-1)
    with pytest.raises(TypeError):
        pendulum.step(1.5)
    with pytest.raises(TypeError):
        pendulum.run('long')
    assert pendulum.step(0) == 0 and pendulum.steps == 0


def test_bad_direct_commands(nscd_sim):
    ball = nscd_sim.Simulator(scene('urdf/ball.urdf'))
    with pytest.raises(ValueError, match="no actuator 'x' \\(actuators: none\\)"):
        ball.set_command('x', 1.0)
    sim = nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=C60_PROBE)
    with pytest.raises(ValueError, match='finite'):
        sim.set_command('probe', math.nan)
    with pytest.raises(ValueError, match='schedule drives'):
        sim.set_command('probe', 0.001)


def test_state_of_another_scene_is_refused(nscd_sim, pendulum):
    ball = nscd_sim.Simulator(scene('urdf/ball.urdf'))
    with pytest.raises(ValueError, match='not made for this model'):
        ball.set_state(pendulum.state())
    with pytest.raises(TypeError):
        ball.set_state('state')


def test_non_finite_state_is_refused(nscd_sim, pendulum):
    t = pendulum.state().__getstate__()
    bodies = t[2].copy()
    bodies[0, 0] = np.nan
    bad = nscd_sim.State.__new__(nscd_sim.State)
    bad.__setstate__((t[0], t[1], bodies) + t[3:])
    with pytest.raises(ValueError, match='non-finite'):
        pendulum.set_state(bad)


@pytest.mark.parametrize('change, message', [
    (lambda t: (99,) + t[1:], 'version'),
    (lambda t: (1,) + t[1:], 'version'),
    (lambda t: t[:5], 'version'),
    (lambda t: t[:2] + (np.zeros((1, 12)),) + t[3:], 'bodies has the wrong shape'),
    (lambda t: t[:5] + (np.zeros(3),) + t[6:], 'warm has the wrong shape'),
    (lambda t: t[:3] + (np.zeros((2, 2)),) + t[4:], 'commands has the wrong shape'),
])
def test_corrupt_pickled_state_is_refused(nscd_sim, pendulum, change, message):
    bad = nscd_sim.State.__new__(nscd_sim.State)
    with pytest.raises(ValueError, match=message):
        bad.__setstate__(change(pendulum.state().__getstate__()))


def state_with_velocities(nscd_sim, state, value):
    t = state.__getstate__()
    bodies = t[2].copy()
    bodies[:, 7:13] = value  # linear and angular velocities
    out = nscd_sim.State.__new__(nscd_sim.State)
    out.__setstate__((t[0], t[1], bodies) + t[3:])
    return out


def test_simulation_error_carries_the_record(nscd_sim):
    """A step that leaves a non-finite state (here: finite but absurd velocities, 1e308 m/s)
    raises SimulationError with nscd_run's message, as nscd_run exits with status 3."""
    sim = nscd_sim.Simulator(scene('urdf/clearance_pendulum.urdf'))
    sim.step(10)
    doomed = state_with_velocities(nscd_sim, sim.state(), 1e308)
    sim.set_state(doomed)
    with pytest.raises(nscd_sim.SimulationError, match='simulation failed at t=.* s: non-finite state') as e:
        sim.run(0.001, every=1)
    assert isinstance(e.value, RuntimeError)
    assert len(e.value.record) == 1  # the start, before the failed step
    sim.set_state(doomed)
    with pytest.raises(nscd_sim.SimulationError) as e:
        sim.step(5)
    assert e.value.record is None
    sim.reset()  # and the simulator still works
    assert sim.step(3) == 3


def test_one_call_at_a_time_and_the_gil_is_released(nscd_sim):
    """While run() steps in a thread, Python keeps running here (the GIL is released) and
    a second call on the same Simulator raises instead of racing it."""
    sim = nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=C60_PROBE)
    done = threading.Event()
    result = {}

    def work():
        result['record'] = sim.run(0.002, every=50)
        done.set()

    worker = threading.Thread(target=work)
    worker.start()
    ticks, refused = 0, 0
    while not done.is_set():
        ticks += 1
        try:
            sim.state()
        except RuntimeError as e:
            assert 'another thread' in str(e)
            refused += 1
        time.sleep(0.001)
    worker.join()
    assert ticks > 10 and refused > 0
    assert len(result['record']) == 1 + 200 // 50


def test_settings_report_the_step_control_in_force(nscd_sim):
    sim = nscd_sim.Simulator(scene('urdf/pendulum.urdf'),
                             settings={'step_control': 'adaptive', 'rtol': 1e-5, 'max_order': 4})
    s = sim.settings
    assert (s['step_control'], s['rtol'], s['max_order']) == ('adaptive', 1e-5, 4)
    assert nscd_sim.Simulator(scene('urdf/pendulum.urdf')).settings['max_order'] == 6
    with pytest.raises(nscd_sim.SceneError, match='max_order'):
        nscd_sim.Simulator(scene('urdf/pendulum.urdf'), settings={'max_order': 1})
