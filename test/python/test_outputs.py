"""The outputs: structured arrays with named fields, consistent with each other."""
import numpy as np
import pytest

from conftest import C60_PROBE, scene


def test_record_fields_are_the_csv_columns_then_the_extras(nscd_sim):
    sim = nscd_sim.Simulator(scene('urdf/clearance_pendulum.urdf'))
    rec = sim.run(0.002, every=10)
    assert rec.dtype.names == tuple(sim.record_fields)
    assert len(rec) == 1 + 200 // 10
    csv = sim.record_fields[:sim.csv_field_count]
    assert csv[0] == 't' and csv[-2:] == ['iters', 'residual']
    assert csv[1:1 + 13 * len(sim.body_names)] == ['%s.%s' % (b, c) for b in sim.body_names for c in
                                                   'x y z qw qx qy qz vx vy vz wx wy wz'.split()]
    assert csv[1 + 13 * len(sim.body_names):-2] == list(sim.key_figures())
    assert rec.dtype['iters'] == np.int32 and rec.dtype['converged'] == np.bool_
    assert np.allclose(np.diff(rec['t']), 10 * sim.dt)
    # The last record is the state now.
    assert rec['t'][-1] == sim.time
    for name, value in sim.key_figures().items():
        assert rec[name][-1] == value, name
    e = sim.energy()
    assert rec['energy_kinetic'][-1] == e['kinetic'] and e['total'] == e['kinetic'] + e['gravity'] + e['springs']
    assert rec['iters'][-1] == sim.stats()['iterations']


def test_bodies_joints_and_clearance_joints_now(nscd_sim):
    sim = nscd_sim.Simulator(scene('urdf/clearance_pendulum.urdf'))
    rec = sim.run(0.01, include_start=False)
    bodies = sim.bodies()
    assert list(bodies['name']) == sim.body_names
    for b in bodies:
        for c in ('x', 'y', 'z', 'qw', 'wz'):
            assert b[c] == rec['%s.%s' % (b['name'], c)][-1]
    joints = sim.joints()
    assert list(joints['name']) == sim.joint_names
    assert joints['qd'][0] == rec[sim.joint_names[0] + '.qd'][-1] and joints['qd'][0] != 0
    cj = sim.clearance_joints()
    assert list(cj['name']) == sim.clearance_joint_names and len(cj) >= 1
    name = cj['name'][0]
    assert cj['ecc'][0] == rec[name + '.ecc'][-1] and cj['fn'][0] == rec[name + '.fn'][-1]
    assert 0 < cj['ecc'][0] < 1.5  # a pendulum swinging in its clearance: off centre


def test_contact_points_of_a_block_resting_on_a_slope(nscd_sim):
    """urdf/slope.urdf: a 1 kg block on a 15 degree slope, mu 0.3 > tan 15: it sticks, the
    normal forces carry m g cos 15 and friction m g sin 15."""
    sim = nscd_sim.Simulator(scene('urdf/slope.urdf'))
    sim.run(0.5, every=1000)
    pts = sim.contact_points()
    assert len(pts) == 4 and set(pts['name']) == {'slide'} and not pts['clearance'].any()
    assert not pts['sliding'].any()
    slope = np.radians(15)
    assert np.allclose(pts['nz'], np.cos(slope)) and np.allclose(np.hypot(pts['nx'], pts['ny']), np.sin(slope))
    contacts = sim.contacts()
    assert list(contacts['name']) == sim.contact_names == ['slide']
    assert contacts['fn'][0] == pytest.approx(pts['fn'].sum())
    assert contacts['fn'][0] == pytest.approx(9.81 * np.cos(slope), rel=1e-3)
    assert contacts['ft'][0] == pytest.approx(9.81 * np.sin(slope), rel=1e-3)
    ft = np.stack([pts['ftx'].sum(), pts['fty'].sum(), pts['ftz'].sum()])
    assert np.linalg.norm(ft) == pytest.approx(contacts['ft'][0])
    stats = sim.stats()
    assert stats['active_contacts'] >= 1 and stats['converged']
    assert stats['substeps'] == 1 and stats['halvings'] == 0  # solved: not taken in halves
    # The step's solves by the solver stage that finished them (a box on a slope:
    # one contact pair of up to 4 points, solved, so none unsolved) and its rescues.
    stages = stats['solver_stages']
    assert list(stages)[:4] == ['no_rows', 'local_solver', 'equalities', 'warm_start'] and len(stages) == 16
    assert sum(stages.values()) >= 1 and stages['unsolved'] == 0 and stages['failed'] == 0
    assert stats['rescues'] == {name: False for name in ('cold_retry', 'plastic_impact', 'halving', 'longer_solve',
                                                         'plastic_retry', 'frictionless', 'energy_cap')}


def test_every_and_include_start(nscd_sim):
    sim = nscd_sim.Simulator(scene('urdf/c60.urdf'), commands=C60_PROBE)
    a = sim.run(0.0001, include_start=False)
    b = sim.run(0.0001, every=3, include_start=True)
    assert len(a) == 10 and len(b) == 1 + 3
    assert b['t'][0] == a['t'][-1]
    assert sim.steps == 20
