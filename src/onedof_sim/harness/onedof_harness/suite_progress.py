"""A pytest plugin that says how far a long run is, for a person watching it: `make test` loads it
(-p onedof_harness.suite_progress). About once a minute, as tests finish, a line such as

    progress: 312/874 tests done (309 passed, 1 failed, 2 skipped), 5 min 10 s so far, about 9 min left

between pytest's own dots (SUITE_PROGRESS_SECONDS in the environment sets how often, 60 by
default); pytest's closing summary line stays as it is. Under pytest-xdist the
line comes from the controlling process, which hears every worker's results; the workers say
nothing. The time left is the time so far per test done, times the tests left: a rough figure
while the long tests, handed out first, still dominate.
"""
import collections
import os
import time

import pytest

DEFAULT_PROGRESS_SECONDS = 60
# The order of the counts on the line; outcomes none of the tests had are left out.
OUTCOMES = ('passed', 'failed', 'error', 'skipped', 'xfailed', 'xpassed')


def duration_text(seconds):
    seconds = int(round(seconds))
    if seconds < 60:
        return '%d s' % seconds
    return '%d min %d s' % divmod(seconds, 60)


def outcome_of(report):
    """What a test's report adds to its outcome: None for a report that passed."""
    if report.failed:
        return 'failed' if report.when in ('call', '???') else 'error'
    if report.skipped:
        return 'xfailed' if hasattr(report, 'wasxfail') else 'skipped'
    if report.when == 'call' and hasattr(report, 'wasxfail'):
        return 'xpassed'
    return None


class SuiteProgress:
    def __init__(self, terminal, interval, clock=time.monotonic):
        self.terminal = terminal
        self.interval = interval
        self.clock = clock
        self.started = self.shown = clock()
        self.total = None
        self.counts = collections.Counter()
        self.outcome = {}  # nodeid -> the outcome so far of a test not yet finished

    # The number of tests: collected here, or by each xdist worker (all collect the same).
    def pytest_collection_finish(self, session):
        self.total = len(session.items)

    @pytest.hookimpl(optionalhook=True)
    def pytest_xdist_node_collection_finished(self, node, ids):
        self.total = len(ids)

    def pytest_runtest_logreport(self, report):
        outcome = outcome_of(report)
        if outcome and self.outcome.get(report.nodeid) in (None, 'passed', 'skipped'):
            self.outcome[report.nodeid] = outcome
        # A test ends with its teardown; a test whose process crashed (pytest-forked, an xdist
        # worker) has a single report instead.
        if report.when not in ('teardown', '???'):
            return
        self.counts[self.outcome.pop(report.nodeid, None) or 'passed'] += 1
        now = self.clock()
        if now - self.shown >= self.interval:
            self.shown = now
            # On a line of its own: pytest's dots fill lines without telling write_line.
            if getattr(getattr(self.terminal, '_tw', None), 'width_of_current_line', 0):
                self.terminal.write('\n')
            self.terminal.write_line(self.line(now))

    def line(self, now):
        done = sum(self.counts.values())
        elapsed = now - self.started
        counts = ', '.join('%d %s' % (self.counts[name], name) for name in OUTCOMES
                           if self.counts[name])
        text = 'progress: %d/%s tests done (%s), %s so far' % (
            done, self.total if self.total is not None else '?', counts,
            duration_text(elapsed))
        if self.total and done < self.total:
            text += ', about %s left' % duration_text(elapsed / done * (self.total - done))
        return text


@pytest.hookimpl(trylast=True)  # after the terminal reporter is there
def pytest_configure(config):
    terminal = config.pluginmanager.get_plugin('terminalreporter')
    if terminal is None or hasattr(config, 'workerinput'):  # no terminal, or an xdist worker
        return
    interval = float(os.environ.get('SUITE_PROGRESS_SECONDS', DEFAULT_PROGRESS_SECONDS))
    config.pluginmanager.register(SuiteProgress(terminal, interval), 'onedof_suite_progress')
