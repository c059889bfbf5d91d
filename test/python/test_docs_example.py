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
    # While they touch, the TRIP contact's normal force is the probe's effort.
    assert abs(rec['TRIP.fn'][touching] - rec['probe.effort'][touching]).max() < 1e-6
    namespace['plt'].close('all')
