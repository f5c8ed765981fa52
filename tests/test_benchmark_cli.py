"""End to end: `rosrun onedof_sim benchmark --quick` measures every item on every engine and writes
the table and the plots. Not a timing test: it checks that each figure was measured and set against
its reference, never how fast anything is."""
import os
import re
import subprocess

from conftest import ENGINES

PNG_MAGIC = b'\x89PNG\r\n\x1a\n'


def table_rows(text):
    """The cells of each row of the Markdown table (header and rule left out)."""
    lines = [line for line in text.splitlines() if line.startswith('| ')]
    return [[cell.strip() for cell in line.strip('|').split(' | ')] for line in lines[1:]]


def test_quick_benchmark_writes_every_row_with_its_comparison(tmp_path):
    output = tmp_path / 'bench'
    # Without profiles: an aim missed only because the machine is busy must not send this test
    # down another path (the profilers are tested on their own, test_profilers.py).
    result = subprocess.run(['rosrun', 'onedof_sim', 'benchmark', '--quick', '--no-profiles',
                             '--output', str(output), '--engines', ','.join(ENGINES)],
                            capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]

    text = (output / 'README-table.md').read_text()
    assert 'Machine: ' in text and ' cores; ' in text
    assert 'failed:' not in text, text
    rows = table_rows(text)
    header = ['#', 'measured', 'figure', 'compared against', 'its figure', 'ratio', 'aim', 'met']
    assert all(len(row) == len(header) for row in rows), rows
    for item, measured, figure, against, against_figure, ratio, aim, met in rows:
        assert figure != 'not measured', (measured, against)
        assert against and against_figure, measured
        assert (aim == '—') == (met == '—'), measured
    # Every item on every engine (the node's _physics:=, the launch's physics:=, the bare loop's
    # --physics), the control loop (4) and lock-step (8, 9) on the default engine.
    expected = {(item, engine) for item in '123567' for engine in ENGINES}
    expected |= {(item, ENGINES[0]) for item in '489'}
    covered = {(row[0], engine) for row in rows for engine in ENGINES
               if re.search(r'physics(:=| )%s\b' % engine, row[1])}
    assert expected <= covered, expected - covered
    # The aims of the issue are each reported, met or not; the Bullet node's against bare
    # pybullet among them.
    aims = [row[6] for row in rows]
    for aim in ('>= 0.5', '>= 0.3', 'p50 <= 1.3x', '0 missed', 'within 1 %',
                'flat: anonymous growth < 2 %'):
        assert aim in aims, aim

    # Lock-step (issue 11): the tutorial with each controller at each rate, with the times the
    # world gave up waiting for it (to be seen, not asserted here: the lock-step tests do).
    lockstep = [row for row in rows if row[0] == '8']
    assert [re.search(r'(rospy|C\+\+) .* at (\d+) Hz', row[1]).groups() for row in lockstep] == [
        ('rospy', '100'), ('C++', '100'), ('rospy', '1000'), ('C++', '1000')], lockstep
    for row in lockstep:
        assert re.search(r"\(lock-step timeouts in the simulator's log: \d+\)$", row[2]), row
    busy = [row[1] for row in rows if row[0] == '9']
    assert len(busy) == 2 and 'lock-stepped' in busy[0] and 'free-running' in busy[1], busy

    plots = ['scaling.png', 'control_loop.png', 'pacing_%s.png' % ENGINES[0]] + [
        'latency_%s.png' % engine for engine in ENGINES]
    for plot in plots:
        with open(os.path.join(output, plot), 'rb') as f:
            assert f.read(8) == PNG_MAGIC, plot
    assert (output / 'results.json').exists()
