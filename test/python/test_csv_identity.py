"""The module's numbers are nscd_run's, bit for bit: the CSV the CLI writes equals the
same columns from Simulator.run formatted as the CLI's writer formats them."""
import difflib

import pytest

from conftest import C60_PROBE, csv_text, run_cli, scene


def assert_same_csv(cli_text, py_text):
    if cli_text != py_text:
        diff = list(difflib.unified_diff(cli_text.splitlines(), py_text.splitlines(), 'nscd_run', 'python', n=0))
        pytest.fail('CSV differs from nscd_run (%d lines):\n%s' % (len(diff), '\n'.join(diff[:12])))


CASES = {
    # name: (nscd_run arguments, Simulator keyword arguments, run keyword arguments)
    'ball': (['urdf/ball.urdf', '--duration', '0.6'], {}, {'duration': 0.6}),
    'clearance_pendulum': (
        ['urdf/clearance_pendulum.urdf', '--duration', '0.03', '--every', '3',
         '--set', 'tolerance=1e-10', '--set', 'theta=0.6'],
        {'settings': {'tolerance': 1e-10, 'theta': 0.6}}, {'duration': 0.03, 'every': 3}),
    # The C-60 trip's first 6.5 ms: settling, the probe moving from 0.7 ms, touching the
    # tripping bar (TRIP closes at 5.5 ms) and the latch's tooth corner taking the load.
    'c60_trip': (['urdf/c60.urdf', '--duration', '0.0065', '--command', C60_PROBE],
                 {'commands': [C60_PROBE]}, {'duration': 0.0065}),
}


@pytest.mark.parametrize('name', sorted(CASES))
def test_module_reproduces_nscd_run_csv(nscd_sim, tmp_path, name):
    cli_args, sim_kwargs, run_kwargs = CASES[name]
    status, stderr, cli_text = run_cli([scene(cli_args[0])] + cli_args[1:], tmp_path)
    assert status == 0, stderr
    sim = nscd_sim.Simulator(scene(cli_args[0]), **sim_kwargs)
    record = sim.run(**run_kwargs)
    assert len(record) == cli_text.count('\n') - 1
    assert_same_csv(cli_text, csv_text(sim, record))
    if name == 'c60_trip':  # the run reached the probe pushing the tripping bar
        assert record['TRIP.fn'].max() > 0.5 and record['probe.cmd'][-1] > 0.9e-3


def test_schedule_as_pairs_is_the_same_schedule(nscd_sim):
    """A schedule given as (time, value) pairs is the text schedule, to the bit."""
    text = nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=C60_PROBE).run(0.0012, every=40)
    pairs = nscd_sim.Simulator(scene('urdf/c60.urdf'),
                               commands={'probe': [(0, 0), (0.0007, 0), (0.0207, 0.004)]}).run(0.0012, every=40)
    assert text.tobytes() == pairs.tobytes()
    assert text['probe.cmd'][-1] > 0  # the probe moved: the schedule was applied


def test_csv_check_sees_a_difference(nscd_sim, tmp_path):
    """The comparison can fail: another tolerance changes the C-60's CSV."""
    status, stderr, cli_text = run_cli([scene('urdf/c60.urdf'), '--duration', '0.0005'], tmp_path)
    assert status == 0, stderr
    sim = nscd_sim.Simulator(scene('urdf/c60.urdf'), settings=['tolerance=1e-6'])
    assert csv_text(sim, sim.run(0.0005)) != cli_text
