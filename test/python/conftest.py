"""Shared by the pytest files: where the repository and nscd_run are, and the CSV
formatting of nscd_run's writer (src/run_output/csv_writer.cpp) in Python."""
import math
import os
import subprocess

import pytest

REPO = os.environ.get('NSCD_SOURCE_DIR') or os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..'))
NSCD_RUN = os.environ.get('NSCD_RUN_EXE') or os.path.join(REPO, '.build', 'ws', 'devel', 'lib', 'nscd_sim', 'nscd_run')

# The C-60 trip's probe schedule (scripts/c60_env.sh).
C60_PROBE = 'probe=0:0,0.0007:0,0.0207:0.004'


def scene(*parts):
    return os.path.join(REPO, *parts)


def run_cli(args, tmp_path):
    """Runs nscd_run ARGS --csv FILE --quiet; returns (exit status, stderr, CSV text or None)."""
    csv = os.path.join(str(tmp_path), 'cli.csv')
    p = subprocess.run([NSCD_RUN] + list(args) + ['--csv', csv, '--quiet'], capture_output=True, text=True)
    text = None
    if os.path.exists(csv):
        with open(csv) as f:
            text = f.read()
    return p.returncode, p.stderr, text


def _c_number(fmt, v):
    """printf(fmt, v) as glibc prints it (Python's % matches it except for a NaN's sign)."""
    if math.isnan(v):
        return '-nan' if math.copysign(1.0, v) < 0 else 'nan'
    return fmt % v


def csv_text(sim, record):
    """The CSV nscd_run's writer would write for these records: its header, then one row
    per record with its formats (%.12g positions, quaternions and joint coordinates,
    %.10g the rest, %d iterations, %.4g the residual)."""
    names = sim.record_fields[:sim.csv_field_count]
    n_body_columns = 13 * len(sim.body_names)
    formats = []
    for k, name in enumerate(names):
        if name == 't':
            formats.append('%.10g')
        elif 1 <= k <= n_body_columns:
            formats.append('%.12g' if name.rsplit('.', 1)[1] in ('x', 'y', 'z', 'qw', 'qx', 'qy', 'qz') else '%.10g')
        elif name.endswith('.q'):
            formats.append('%.12g')
        elif name == 'iters':
            formats.append('%d')
        elif name == 'residual':
            formats.append('%.4g')
        else:
            formats.append('%.10g')
    lines = [','.join(names)]
    for row in record:
        lines.append(','.join(_c_number(f, row[n].item()) for f, n in zip(formats, names)))
    return '\n'.join(lines) + '\n'


@pytest.fixture(scope='session')
def nscd_sim():
    import nscd_sim as module
    return module
