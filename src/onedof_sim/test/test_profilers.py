"""The benchmark's profilers: `make setup` installs both (perf from linux-perf,
py-spy in the venv) and they work; a missing one is said plainly, never a failure. Run on a
spinning process, so the profiling path is tested on every run, not only when a busy machine
makes the benchmark miss an aim."""
import os
import subprocess
import sys

import pytest

from onedof_sim.benchmark import profiling


@pytest.fixture
def spinner():
    proc = subprocess.Popen([sys.executable, '-c', 'while True: pass'])
    yield proc
    proc.kill()
    proc.wait()


def test_perf_profiles_a_busy_process(spinner, tmp_path):
    path = str(tmp_path / 'profile_perf.txt')
    summary = profiling.take_profile(spinner.pid, 1, path)
    assert summary.startswith('perf, 1 s of on-CPU samples: by object '), summary
    assert 'python' in summary, summary
    assert os.path.getsize(path) > 0


def test_py_spy_profiles_a_busy_python_process(spinner, tmp_path):
    path = str(tmp_path / 'profile_pyspy.txt')
    summary = profiling.take_profile(spinner.pid, 1, path, python=True)
    assert summary.startswith('py-spy, 1 s of samples of the thread running Python: '), summary
    assert '<module>' in open(path).read()


def test_a_missing_profiler_is_said_plainly(spinner, tmp_path, monkeypatch):
    monkeypatch.setenv('PATH', str(tmp_path))
    monkeypatch.setattr(profiling, 'workspace_venv_bin', lambda: str(tmp_path))
    assert profiling.take_profile(spinner.pid, 1, str(tmp_path / 'a.txt')) == (
        'no profile: perf is not installed (Debian package linux-perf)')
    assert profiling.take_profile(spinner.pid, 1, str(tmp_path / 'b.txt'), python=True) == (
        'no profile: py-spy is not installed (make venv installs it)')
