"""Runs every gtest case of the workspace (binaries named *_test in the devel space) as one pytest
item each, so one runner reports and counts every test."""
import glob
import os
import subprocess
import tempfile
import time

import pytest


def devel_dirs():
    return [p for p in os.environ.get('CMAKE_PREFIX_PATH', '').split(':')
            if p and os.path.isfile(os.path.join(p, '.catkin'))]


def gtest_binaries():
    for devel in devel_dirs():
        for path in sorted(glob.glob(os.path.join(devel, 'lib', '*', '*_test'))):
            if os.access(path, os.X_OK):
                yield path


def gtest_cases():
    cases = []
    for binary in gtest_binaries():
        listing = subprocess.run([binary, '--gtest_list_tests'], capture_output=True, text=True,
                                 check=True).stdout
        suite = None
        for line in listing.splitlines():
            if not line.strip() or line.startswith('Running main'):
                continue
            if not line.startswith(' '):
                suite = line.split('#')[0].strip()
            else:
                case = line.split('#')[0].strip()
                cases.append(pytest.param(binary, suite + case,
                                          id='%s:%s%s' % (os.path.basename(binary), suite, case)))
    return cases


# A case is a hang once its process has had no CPU time for this long; a busy machine only slows
# it. Cases differ a hundredfold in their CPU time (an engine's inertia sweep steps thousands of
# bodies), and at load 20 a process gets a tenth of a core: a wall-clock bound short enough to
# catch a hang soon would fail the heavy cases on a busy machine.
HANG_SECONDS = 300
# Only a bound on a case that keeps computing for ever.
CASE_TIMEOUT = 3600


def cpu_seconds(pid):
    """The user and system CPU time of process pid so far (s)."""
    with open('/proc/%d/stat' % pid) as f:
        fields = f.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def run_case(binary, case):
    """Runs one gtest case to its end; fails it when it stops using CPU for HANG_SECONDS."""
    with tempfile.TemporaryFile('w+') as out:
        proc = subprocess.Popen([binary, '--gtest_filter=' + case], stdout=out,
                                stderr=subprocess.STDOUT, text=True)
        used, progressed = 0.0, time.monotonic()
        try:
            while proc.poll() is None:
                try:
                    proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    now_used = cpu_seconds(proc.pid)
                    if now_used > used:
                        used, progressed = now_used, time.monotonic()
                    elif time.monotonic() - progressed > HANG_SECONDS:
                        pytest.fail('%s hung: no CPU time for %d s (%.1f s used)'
                                    % (case, HANG_SECONDS, used))
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        out.seek(0)
        return proc.returncode, out.read()


@pytest.mark.timeout(CASE_TIMEOUT)
@pytest.mark.parametrize('binary,case', gtest_cases())
def test_gtest_case(binary, case):
    returncode, output = run_case(binary, case)
    assert returncode == 0, output[-8000:]
    assert '[  PASSED  ] 1 test' in output, output[-3000:]


def test_gtest_binaries_were_built():
    assert list(gtest_binaries()), 'no *_test binary in %s: was the workspace built with tests?' % (
        devel_dirs(),)
