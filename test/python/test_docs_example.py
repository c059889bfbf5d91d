"""docs/python.md's ten-line example runs as written (the scene path made absolute, the
figure written to a temporary folder) and plots a tripping force."""
import os
import re

from conftest import REPO


def example_code():
    with open(os.path.join(REPO, 'docs', 'python.md')) as f:
        doc = f.read()
    section = doc.split('## Ten lines', 1)[1]
    return re.search(r'```python\n(.*?)```', section, re.S).group(1)


def test_the_ten_line_example_runs(tmp_path, monkeypatch):
    code = example_code()
    assert len([line for line in code.splitlines() if line.strip()]) <= 10
    monkeypatch.setenv('MPLBACKEND', 'Agg')
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(code.replace("'urdf/", "'" + REPO + "/urdf/"), 'docs/python.md', 'exec'), namespace)
    assert (tmp_path / 'c60_trip_force.png').stat().st_size > 10000
    rec = namespace['rec']
    touching = rec['TRIP.fn'] > 0
    assert touching.any()
    # While they touch, the probe's effort (the force along its prescribed axis) is the TRIP
    # contact's normal force, plus what the plunger bearing takes along the axis (its
    # friction, and its normal force's share on the tilted probe), plus the axial part of
    # TRIP's friction on the tilted face. The probe tilts by under 0.05 rad in its bore
    # (diametral gap 0.198 mm over a guided length >= 4.6 mm); solver tolerance 1e-5 of fn.
    t = touching
    fn, effort = rec['TRIP.fn'][t], rec['probe.effort'][t]
    tilt = 0.05
    bearing = sum(rec[n + '.ft'][t] + tilt * rec[n + '.fn'][t]
                  for n in ('plunger_bearing', 'plunger_bearing_front', 'plunger_bearing_mouth'))
    bound = bearing + tilt * rec['TRIP.ft'][t] + (tilt ** 2 / 2 + 1e-5) * abs(fn) + 1e-8
    assert (abs(fn - effort) <= bound).all()
    namespace['plt'].close('all')
