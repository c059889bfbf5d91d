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
    # While they touch, the TRIP contact's normal force is the probe's effort (to the
    # solver's tolerance: 1e-9 N mostly, 5e-6 of the force at two samples).
    fn, effort = rec['TRIP.fn'][touching], rec['probe.effort'][touching]
    assert (abs(fn - effort) <= 1e-5 * abs(fn) + 1e-8).all()
    namespace['plt'].close('all')
