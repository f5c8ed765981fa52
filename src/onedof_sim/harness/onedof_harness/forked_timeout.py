"""A pytest plugin for the suite as `make test` runs it (-p onedof_harness.forked_timeout): xdist
workers, each test in a process forked from its worker (pytest-forked), and pytest-timeout's
thread method. A test still running at the timeout ends its worker, which xdist reports as that
test's failure and replaces, and the run goes on. The test's own process would run on without it
(for ever, if it hangs) and keep the pipe the run reads its worker through open, so that the run
never ended: it is told when its worker goes (Linux's parent-death signal, SIGTERM) and fails
where it is, its fixtures stopping what it started.
"""
import ctypes
import os
import signal

import pytest

PR_SET_PDEATHSIG = 1
worker_pid = None  # the process that forks the tests
worker_gone_told = False  # in a test's process: whether the test was failed for its worker's end


def pytest_configure(config):
    global worker_pid
    worker_pid = os.getpid()


def worker_gone(signum, frame):
    """Fails the test once. The signal can come more than once: Linux sends it each time the
    thread that forked the test ends and the test passes to the worker's next live thread, and
    the worker's threads end one after another. A second failure raised in the first one's
    report or teardown would end the test's process with its fixtures still up."""
    global worker_gone_told
    if worker_gone_told:
        return
    worker_gone_told = True
    pytest.fail("the test's pytest worker ended (the suite's timeout); the test was stopped",
                pytrace=False)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    if os.getpid() == worker_pid:  # the test runs in the worker itself, not forked
        return
    signal.signal(signal.SIGTERM, worker_gone)
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != worker_pid:  # gone already, before the signal was asked for
        os.kill(os.getpid(), signal.SIGTERM)
