"""A pytest plugin that says how far a long run is, for a person watching it: `make test` loads it
(-p onedof_harness.suite_progress). About once a minute a line such as

    progress: 312/874 tests done (309 passed, 1 failed, 2 skipped), 6 running, 5 min 10 s so far,
    about 9 min 0 s left (on one line)

between pytest's own dots (SUITE_PROGRESS_SECONDS in the environment sets how often, 60 by
default; 0: after every test), also while no test ends (the long ones, handed out first, take
minutes each on a busy machine); pytest's closing summary line stays as it is. Under pytest-xdist
the line comes from the controlling process, which hears every worker's results; the workers say
nothing. The time left is the tests left at the pace of the latest RECENT_TESTS to end (of all
so far until that many have): the long tests, handed out first, make early figures high.

A test that fails or errors is named at once, on a line of its own,

    failed: tests/test_api.py::test_spawn[bullet] (after 12 min 3 s; its report comes at the end)

so that a person watching a long run knows what broke without waiting for pytest's summary.
"""
import collections
import os
import threading
import time

import pytest

DEFAULT_PROGRESS_SECONDS = 60
RECENT_TESTS = 100
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
    """The counts, and the line when one is due: after a test ends, and from a thread of its own
    while none does. The lock keeps that thread's line off the lines pytest writes as a test
    starts or ends."""

    def __init__(self, terminal, interval, clock=time.monotonic):
        self.terminal = terminal
        self.interval = interval
        self.clock = clock
        self.started = self.shown = clock()
        self.total = None
        self.counts = collections.Counter()
        self.outcome = {}  # nodeid -> the outcome so far of a test not yet finished
        self.running = set()
        self.ended = collections.deque(maxlen=RECENT_TESTS)  # when the latest tests ended
        self.lock = threading.Lock()
        self.finished = threading.Event()
        self.timer = None

    # The number of tests: collected here, or by each xdist worker (all collect the same).
    def pytest_collection_finish(self, session):
        self.total = len(session.items)

    @pytest.hookimpl(optionalhook=True)
    def pytest_xdist_node_collection_finished(self, node, ids):
        self.total = len(ids)

    def pytest_sessionstart(self, session):
        if self.interval > 0:
            self.timer = threading.Thread(target=self.show_while_no_test_ends, daemon=True,
                                          name='suite progress')
            self.timer.start()

    @pytest.hookimpl(tryfirst=True)  # before pytest's summary
    def pytest_sessionfinish(self, session):
        with self.lock:
            self.finished.set()

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_logstart(self, nodeid, location):
        with self.lock:
            self.running.add(nodeid)
            yield

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_logreport(self, report):
        with self.lock:
            yield  # pytest's own dot first
            outcome = outcome_of(report)
            if outcome and self.outcome.get(report.nodeid) in (None, 'passed', 'skipped'):
                self.outcome[report.nodeid] = outcome
            # A test ends with its teardown; a test whose process crashed (pytest-forked, an
            # xdist worker) has a single report instead.
            if report.when in ('teardown', '???'):
                self.running.discard(report.nodeid)
                outcome = self.outcome.pop(report.nodeid, None) or 'passed'
                self.counts[outcome] += 1
                self.ended.append(self.clock())
                if outcome in ('failed', 'error'):
                    self.write_own_line('%s: %s (after %s; its report comes at the end)' % (
                        outcome, report.nodeid, duration_text(self.clock() - self.started)))
                self.show_if_due()

    def show_while_no_test_ends(self):
        while not self.finished.wait(max(0.1, self.shown + self.interval - self.clock())):
            with self.lock:
                if not self.finished.is_set():
                    self.show_if_due()

    def show_if_due(self):
        now = self.clock()
        if now - self.shown < self.interval:
            return
        self.shown = now
        self.write_own_line(self.line(now))

    def write_own_line(self, text):
        # On a line of its own: pytest's dots fill lines without telling write_line.
        if getattr(getattr(self.terminal, '_tw', None), 'width_of_current_line', 0):
            self.terminal.write('\n')
        self.terminal.write_line(text)

    def line(self, now):
        done = sum(self.counts.values())
        elapsed = now - self.started
        text = 'progress: %d/%s tests done' % (done, self.total if self.total is not None else '?')
        counts = ', '.join('%d %s' % (self.counts[name], name) for name in OUTCOMES
                           if self.counts[name])
        if counts:
            text += ' (%s)' % counts
        if self.running:
            text += ', %d running' % len(self.running)
        text += ', %s so far' % duration_text(elapsed)
        if done and self.total and done < self.total:
            text += ', about %s left' % duration_text((self.total - done) / self.pace(now))
        return text

    def pace(self, now):
        """Tests ended per second: of the latest RECENT_TESTS, or of all until that many have."""
        if len(self.ended) < self.ended.maxlen:
            return len(self.ended) / max(now - self.started, 1e-9)
        return (len(self.ended) - 1) / max(now - self.ended[0], 1e-9)


@pytest.hookimpl(trylast=True)  # after the terminal reporter is there
def pytest_configure(config):
    terminal = config.pluginmanager.get_plugin('terminalreporter')
    if terminal is None or hasattr(config, 'workerinput'):  # no terminal, or an xdist worker
        return
    interval = float(os.environ.get('SUITE_PROGRESS_SECONDS', DEFAULT_PROGRESS_SECONDS))
    config.pluginmanager.register(SuiteProgress(terminal, interval), 'onedof_suite_progress')
