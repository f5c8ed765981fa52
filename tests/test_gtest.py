"""Runs every gtest case of the workspace (binaries named *_test in the devel space) as one pytest
item each, so one runner reports and counts every test."""
import glob
import os
import subprocess

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


@pytest.mark.parametrize('binary,case', gtest_cases())
def test_gtest_case(binary, case):
    # The timeout only bounds a hang, below pytest's 900 s: a case of 20 CPU-seconds took 530 s
    # at load 30.
    result = subprocess.run([binary, '--gtest_filter=' + case], capture_output=True, text=True,
                            timeout=850)
    assert result.returncode == 0, result.stdout[-6000:] + result.stderr[-2000:]
    assert '[  PASSED  ] 1 test' in result.stdout, result.stdout[-3000:]


def test_gtest_binaries_were_built():
    assert list(gtest_binaries()), 'no *_test binary in %s: was the workspace built with tests?' % (
        devel_dirs(),)
