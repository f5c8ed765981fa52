"""The suite's runner (make test: xdist workers, each test forked, pytest-timeout's thread method,
onedof_harness.forked_timeout) with a test that never ends: at the timeout that test fails, its
fixtures tear down, and the run goes on to its closing summary."""
import os
import re
import signal
import subprocess
import sys
import textwrap

import pytest

from onedof_harness import forked_timeout
from onedof_harness.private_ros import wait_until

SUITE = textwrap.dedent('''
    import os
    import signal
    import threading

    import pytest

    @pytest.fixture
    def started():
        yield
        # Told again that the worker went, as the worker's other threads end after the one
        # that forked this test: the teardown goes on.
        os.kill(os.getpid(), signal.SIGTERM)
        with open(os.environ['TORN_DOWN'], 'w') as f:
            f.write('torn down')

    def test_passes():
        pass

    def test_never_ends(started):
        threading.Event().wait()

    def test_passes_too():
        pass
''')
# When the never-ending test counts as hung; far above what the others take on a busy machine.
TEST_TIMEOUT = 60
# Only a bound on a hang of the run itself.
HANG_SECONDS = 600


def test_a_test_that_never_ends_fails_at_the_timeout_and_the_run_reaches_its_summary(tmp_path):
    (tmp_path / 'test_sample.py').write_text(SUITE)
    torn_down = tmp_path / 'torn_down'
    result = subprocess.run(
        [sys.executable, '-m', 'pytest', '-p', 'no:cacheprovider', '-p',
         'onedof_harness.forked_timeout', '-n', '2', '--forked', '--timeout=%d' % TEST_TIMEOUT,
         '--timeout-method=thread', str(tmp_path)],
        capture_output=True, text=True, cwd=str(tmp_path), timeout=HANG_SECONDS,
        env=dict(os.environ, TORN_DOWN=str(torn_down)))
    assert re.search(r'=+ 1 failed, 2 passed in [\d.]+s', result.stdout), result.stdout
    assert "crashed while running 'test_sample.py::test_never_ends'" in result.stdout
    # The test's own process, told its worker went, failed there and tore its fixture down.
    wait_until(lambda: torn_down.exists(), HANG_SECONDS, what="the test's fixture torn down")


def test_the_test_is_failed_once_however_often_its_worker_going_is_told(monkeypatch):
    monkeypatch.setattr(forked_timeout, 'worker_gone_told', False)
    with pytest.raises(pytest.fail.Exception, match='worker ended'):
        forked_timeout.worker_gone(signal.SIGTERM, None)
    forked_timeout.worker_gone(signal.SIGTERM, None)
