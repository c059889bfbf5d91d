"""State files: Simulator.save_state / load_state and nscd_run --initial-state /
--save-state write and read one format, so a run moves between them bit for bit."""
import subprocess

import pytest

from conftest import C60_PROBE, NSCD_RUN, scene


def c60(nscd_sim):
    return nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=C60_PROBE)


def test_python_and_nscd_run_continue_alike(nscd_sim, tmp_path):
    """Saved by Python, continued by nscd_run, read back by Python: the state Python
    reaches by continuing itself, bit for bit."""
    sim = c60(nscd_sim)
    sim.step(80)
    start = tmp_path / 'start.state'  # an os.PathLike
    sim.save_state(start)
    sim.run(0.0004, include_start=False)
    reference = sim.state()

    end = str(tmp_path / 'end.state')
    p = subprocess.run([NSCD_RUN, scene('urdf/c60.urdf'), '--command', C60_PROBE, '--duration', '0.0004',
                        '--initial-state', str(start), '--save-state', end, '--quiet'],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    other = c60(nscd_sim)
    other.load_state(end)
    assert other.state() == reference
    assert other.steps == sim.steps  # the fixed steps' clock follows the state's time

    other.load_state(start)  # and back: the state saved
    sim2 = c60(nscd_sim)
    sim2.step(80)
    assert other.state() == sim2.state()


def test_a_state_of_another_scene_is_refused(nscd_sim, tmp_path):
    pendulum = nscd_sim.Simulator(scene('urdf/clearance_pendulum.urdf'))
    path = str(tmp_path / 'pendulum.state')
    pendulum.save_state(path)
    sim = c60(nscd_sim)
    sim.step(5)
    before = sim.state()
    with pytest.raises(nscd_sim.StateFileError, match='another scene') as e:
        sim.load_state(path)
    assert isinstance(e.value, ValueError)
    assert str(e.value).startswith(path + ':')
    assert sim.state() == before


def test_a_damaged_file_and_an_unwritable_path_are_refused(nscd_sim, tmp_path):
    sim = c60(nscd_sim)
    path = tmp_path / 'c60.state'
    sim.save_state(path)
    text = path.read_text()
    path.write_text(text.replace('body 1 ', 'body 1 -', 1))
    with pytest.raises(nscd_sim.StateFileError, match='checksum differs'):
        sim.load_state(path)
    path.write_text(text[:len(text) // 2])
    with pytest.raises(nscd_sim.StateFileError, match='truncated'):
        sim.load_state(path)
    with pytest.raises(nscd_sim.StateFileError, match='cannot write'):
        sim.save_state(tmp_path / 'no_such_folder' / 'x.state')
