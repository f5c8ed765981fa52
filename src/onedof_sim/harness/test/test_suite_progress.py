"""The suite's progress lines (onedof_harness.suite_progress): how many tests of how many are done
with their outcomes so far, how many run, the time so far and about how long is left, from the
process that hears every result, as `make test` runs the suite (xdist workers, each test forked),
also while no test ends; pytest's closing summary stays."""
import collections
import os
import re
import subprocess
import sys
import textwrap
from types import SimpleNamespace

import pytest

from onedof_harness.suite_progress import SuiteProgress, duration_text

TESTS = textwrap.dedent('''
    import pytest

    def test_passes():
        pass

    def test_passes_too():
        pass

    def test_fails():
        assert False

    def test_skips():
        pytest.skip('not here')

    @pytest.fixture
    def broken():
        raise RuntimeError('set-up fails')

    def test_errors(broken):
        pass
''')


# A test that ends only once the suite's output has a line saying it runs.
WAITS_FOR_ITS_LINE = textwrap.dedent('''
    import os
    from onedof_harness.private_ros import wait_until

    def test_ends_once_a_line_says_it_runs():
        wait_until(lambda: 'progress: 0/1 tests done, 1 running, ' in
                   open(os.environ['SUITE_OUTPUT']).read(), 300, what='a progress line')
''')
# Only a bound against a hang.
HANG_SECONDS = 600


def run_suite(tmp_path, *args, tests=TESTS, interval='0', stdout=subprocess.PIPE):
    (tmp_path / 'test_sample.py').write_text(tests)
    return subprocess.run(
        [sys.executable, '-m', 'pytest', '-p', 'no:cacheprovider', '-p',
         'onedof_harness.suite_progress'] + list(args) + [str(tmp_path)],
        stdout=stdout, stderr=subprocess.STDOUT, text=True, cwd=str(tmp_path),
        timeout=HANG_SECONDS, env=dict(os.environ, SUITE_PROGRESS_SECONDS=interval,
                                       SUITE_OUTPUT=str(tmp_path / 'output')))


def progress_lines(stdout):
    return [line for line in stdout.splitlines() if line.startswith('progress: ')]


def test_each_line_says_how_far_the_forked_suite_on_workers_is_and_the_summary_stays(tmp_path):
    result = run_suite(tmp_path, '-n', '2', '--forked')
    lines = progress_lines(result.stdout)
    # Every test's end gives a line here (a line at most every 0 s).
    assert len(lines) == 5, result.stdout
    for done, line in enumerate(lines, 1):
        # Durations of a minute and more read `1 min 0 s` (a busy machine's tests take that).
        duration = r'(\d+ min )?\d+ s'
        assert re.fullmatch(r'progress: %d/5 tests done \((\d+ \w+)(, \d+ \w+)*\)'
                            r'(, [12] running)?, %s so far(, about %s left)?'
                            % (done, duration, duration), line), line
        assert ('about' in line) == (done < 5), line
    assert lines[-1].startswith(
        'progress: 5/5 tests done (2 passed, 1 failed, 1 error, 1 skipped), ')
    assert 'running' not in lines[-1]
    assert re.search(r'=+ 1 failed, 2 passed, 1 skipped, 1 error in [\d.]+s', result.stdout), \
        result.stdout
    assert_failures_named_as_they_end(result.stdout)


def assert_failures_named_as_they_end(stdout):
    """The failed and the erring test each named once on a line of their own, before pytest's
    summary; no other test named so."""
    named = re.findall(r'^(failed|error): (\S+) \(after (?:\d+ min )?\d+ s; its report comes at '
                       r'the end\)$', stdout, re.M)
    assert sorted(named) == [('error', 'test_sample.py::test_errors'),
                             ('failed', 'test_sample.py::test_fails')], stdout
    summary = stdout.index('= FAILURES =')
    assert all(stdout.index('%s: %s (' % pair) < summary for pair in named), stdout


def test_without_workers_too(tmp_path):
    result = run_suite(tmp_path)
    lines = progress_lines(result.stdout)
    assert len(lines) == 5, result.stdout
    assert lines[-1].startswith(
        'progress: 5/5 tests done (2 passed, 1 failed, 1 error, 1 skipped), ')
    assert_failures_named_as_they_end(result.stdout)


def test_a_line_comes_while_no_test_ends(tmp_path):
    with open(tmp_path / 'output', 'w') as output:
        result = run_suite(tmp_path, '-n', '2', '--forked', tests=WAITS_FOR_ITS_LINE,
                           interval='1', stdout=output)
    text = (tmp_path / 'output').read_text()
    assert result.returncode == 0, text
    assert re.search(r'^progress: 0/1 tests done, 1 running, (\d+ min )?\d+ s so far$', text, re.M), \
        text
    assert re.search(r'=+ 1 passed in [\d.]+s', text), text


def report(nodeid, when, outcome='passed'):
    return SimpleNamespace(nodeid=nodeid, when=when, failed=outcome == 'failed',
                           skipped=outcome == 'skipped', passed=outcome == 'passed')


def hear(progress, report):
    """Calls the plugin's hook as pytest does: a wrapper around pytest's own."""
    hook = progress.pytest_runtest_logreport(report)
    next(hook)
    with pytest.raises(StopIteration):
        hook.send(None)


def test_a_line_at_most_every_interval_with_the_time_left_at_the_pace_so_far():
    written, now = [], [0.0]
    progress = SuiteProgress(SimpleNamespace(write_line=written.append), 60,
                             clock=lambda: now[0])
    progress.total = 10
    for k, at in enumerate((30, 59, 61, 100, 110), 1):
        now[0] = at
        for when in ('setup', 'call', 'teardown'):
            hear(progress, report('t%d' % k, when))
    # A crashed forked test: one report, failed.
    now[0] = 300
    hear(progress, report('t6', '???', 'failed'))
    assert written == ['progress: 3/10 tests done (3 passed), 1 min 1 s so far, '
                       'about 2 min 22 s left',
                       'failed: t6 (after 5 min 0 s; its report comes at the end)',
                       'progress: 6/10 tests done (5 passed, 1 failed), 5 min 0 s so far, '
                       'about 3 min 20 s left']


def test_durations_read_as_minutes_and_seconds():
    assert [duration_text(s) for s in (0, 59.4, 60, 3725)] == ['0 s', '59 s', '1 min 0 s',
                                                                '62 min 5 s']


def test_the_time_left_is_at_the_pace_of_the_latest_tests():
    written, now = [], [0.0]
    progress = SuiteProgress(SimpleNamespace(write_line=written.append), 0, clock=lambda: now[0])
    progress.total = 10
    progress.ended = collections.deque(maxlen=3)
    # Three long tests, then short ones: the last three ended 1 s apart.
    for k, at in enumerate((100, 200, 300, 301, 302), 1):
        now[0] = at
        hear(progress, report('t%d' % k, 'teardown'))
    assert written[-1] == 'progress: 5/10 tests done (5 passed), 5 min 2 s so far, about 5 s left'
