"""Set-up output: one line per step, saying what is installed or built and how long it took; a
step that runs long prints a progress line every few seconds; the full output in a log file,
written as it comes; a failing step prints its own output in full. CMake's "nosetests not found"
and "GMock is not available" (true, and irrelevant here) stay in the log."""
import os
import re
import subprocess

import pytest

from conftest import WORKSPACE

STEP = os.path.join(WORKSPACE, 'scripts', 'step')
# Only a bound against a hang (s).
HANG_SECONDS = 300


def step(log, what, *command):
    return subprocess.run([STEP, str(log), what] + list(command), capture_output=True, text=True,
                          cwd=str(log.parent))


def test_a_step_prints_one_line_and_logs_its_output(tmp_path):
    log = tmp_path / 'setup.log'
    result = step(log, 'build: catkin_make', 'sh', '-c',
                  'echo "-- nosetests not found, Python tests can not be run"; echo warning >&2')
    assert result.returncode == 0, result.stderr
    assert re.fullmatch(r'build: catkin_make \.\.\. done in \d+ s \(full output: setup\.log\)\n',
                        result.stdout), result.stdout
    assert result.stderr == ''
    text = log.read_text()
    assert 'build: catkin_make' in text and 'nosetests not found' in text and 'warning' in text


def test_a_failing_step_prints_its_output_and_exits_with_its_status(tmp_path):
    log = tmp_path / 'setup.log'
    step(log, 'first', 'true')
    result = step(log, 'deps: apt-get update', 'sh', '-c', 'echo line 1; echo "E: no network" >&2; '
                  'exit 100')
    assert result.returncode == 100
    lines = result.stdout.splitlines()
    assert lines[0].startswith('deps: apt-get update ... FAILED (exit 100) after ')
    assert lines[1:3] == ['line 1', 'E: no network']
    assert str(log) in lines[-1]
    assert 'first' in log.read_text() and 'E: no network' in log.read_text()


def test_every_install_and_build_command_of_the_set_up_is_a_step():
    # -B: the plan of a first run (everything out of date); -n: print it, run nothing.
    plan = subprocess.run(['make', '-n', '-B', '-C', WORKSPACE, 'setup', 'BUILD=build_plan',
                           'DEVEL=devel_plan'], capture_output=True, text=True, check=True).stdout
    commands = [command for line in plan.replace('\\\n', ' ').splitlines()
                for command in line.split(';')]
    for tool in ('apt-get update', 'apt-get install', 'pip install', 'catkin_make'):
        # A simulated install (-s: how many packages an install brings) installs nothing.
        runs = [command for command in commands
                if tool in command and 'apt-get install -s ' not in command]
        assert runs, tool
        for command in runs:
            assert 'scripts/step ' in command.split(tool)[0], command


def progress_step(tmp_path, what, script):
    """Runs a step with a 1 s progress interval whose command is `script` (sh) and which may call
    `wait_for_progress TEXT`: it returns once the step has printed TEXT (bounded against a hang), so
    the command stays alive exactly until the progress line it waits for is out."""
    log, shown = tmp_path / 'setup.log', tmp_path / 'stdout'
    helper = ('wait_for_progress() { i=0; until grep -q "$1" %s; do i=$((i+1)); '
              '[ $i -gt %d ] && exit 9; sleep 0.1; done; }; ' % (shown, HANG_SECONDS * 10))
    with open(shown, 'w') as out:
        result = subprocess.run([STEP, str(log), what, 'sh', '-c', helper + script],
                                stdout=out, stderr=subprocess.STDOUT, text=True, cwd=str(tmp_path),
                                env=dict(os.environ, STEP_PROGRESS_SECONDS='1'),
                                timeout=4 * HANG_SECONDS)
    return result.returncode, shown.read_text(), log.read_text()


def test_a_long_package_install_shows_how_many_packages_are_downloaded_unpacked_and_set_up(tmp_path):
    status, shown, log = progress_step(tmp_path, 'deps: installing 3 Debian packages (2 named)', (
        'echo "0 upgraded, 3 newly installed, 0 to remove"; echo "Get:1 http://deb a"; '
        'wait_for_progress "1 of 3 downloaded, 0 unpacked, 0 set up"; '
        'echo "Get:2 http://deb b"; echo "Unpacking a"; echo "Unpacking b"; '
        'wait_for_progress "2 of 3 downloaded, 2 unpacked, 0 set up"; '
        'echo "Setting up a"; wait_for_progress "2 of 3 downloaded, 2 unpacked, 1 set up"'))
    assert status == 0, shown
    lines = shown.splitlines()
    assert lines[0] == 'deps: installing 3 Debian packages (2 named) ... '
    assert re.fullmatch(r'deps: installing 3 Debian packages \(2 named\) \.\.\. done in \d+ s '
                        r'\(full output: setup\.log\)', lines[-1])
    progress = lines[1:-1]
    assert progress and all(re.fullmatch(r'  deps: installing 3 Debian packages: \d of 3 '
                                         r'downloaded, \d unpacked, \d set up \(\d+ s\)',
                                         line) for line in progress), progress
    assert 'Setting up a' in log


def test_a_long_build_shows_its_percentage_and_logs_as_it_goes(tmp_path):
    log = tmp_path / 'setup.log'
    status, shown, _ = progress_step(tmp_path, 'build: catkin_make', (
        'echo "[ 42%%] Building CXX object onedof_sim/CMakeFiles/world.cpp.o"; '
        # The log holds the line while the step still runs.
        'grep -q "Building CXX" %s || exit 8; wait_for_progress "42%%"' % log))
    assert status == 0, shown
    assert '  build: catkin_make: [ 42%] Building CXX object onedof_sim/CMakeFiles/world.cpp.o (' \
        in shown


def test_the_deps_step_says_how_many_packages_apt_installs_and_logs_their_names(tmp_path):
    """With every package missing (a fake dpkg-query knows none) and a fake apt-get whose simulated
    install brings 5 more than it is given: the step's line counts them; the names are in the log
    only."""
    fake = tmp_path / 'bin'
    fake.mkdir()
    (fake / 'dpkg-query').write_text('#!/bin/sh\nexit 1\n')
    (fake / 'apt-get').write_text(
        '#!/bin/sh\n'
        'case "$*" in\n'
        '  *" -s "*) shift 3; for p in "$@" extra1 extra2 extra3 extra4 extra5; do\n'
        '              echo "Inst $p (1.0 Debian:12/stable [amd64])"; done;;\n'
        '  *install*) echo "Setting up everything";;\n'
        'esac\n')
    (fake / 'sudo').write_text('#!/bin/sh\nexec "$@"\n')
    for tool in fake.iterdir():
        tool.chmod(0o755)
    log = tmp_path / 'setup.log'
    plan = subprocess.run(['make', '-s', '-C', WORKSPACE, '-p', '-n', 'deps'], capture_output=True,
                          text=True).stdout
    packages = re.search(r'^APT_PACKAGES := (.*)$', plan, re.M).group(1).split()
    result = subprocess.run(['make', '-s', '-C', WORKSPACE, 'deps', 'SETUP_LOG=%s' % log],
                            capture_output=True, text=True, timeout=HANG_SECONDS,
                            env=dict(os.environ, PATH='%s:%s' % (fake, os.environ['PATH'])))
    assert result.returncode == 0, result.stdout + result.stderr
    install_line = [line for line in result.stdout.splitlines() if 'deps: installing' in line]
    assert install_line == [
        "deps: installing %d Debian packages (the workspace's %d and what they depend on, the "
        'names in %s) '
        '... done in %s' % (len(set(packages)) + 5, len(set(packages)), log,
                            install_line[0].split(' done in ')[-1])], result.stdout
    assert not any(package in result.stdout for package in ('libode-dev', 'python3-rospy'))
    assert 'libode-dev' in log.read_text() and 'Setting up everything' in log.read_text()


def test_set_up_warns_when_the_host_name_does_not_resolve():
    """Run on a machine whose host name has no /etc/hosts line (a UTS namespace with a name that
    cannot resolve), set-up's host check warns, names the line to add, and does not fail; on this
    machine, as it is, it says nothing when the name resolves."""
    made = subprocess.run(['unshare', '--uts', 'true'], capture_output=True, text=True)
    if made.returncode != 0:
        pytest.skip('no UTS namespace can be made here: %s' % made.stderr.strip())
    name = 'onedof-nowhere.invalid'  # RFC 6761: never resolves
    result = subprocess.run(['unshare', '--uts', 'sh', '-c', 'hostname %s && exec make '
                             '--no-print-directory -C %s host' % (name, WORKSPACE)],
                            capture_output=True, text=True, timeout=HANG_SECONDS)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout == (
        "set-up: warning: this machine's host name '%s' does not resolve: roslaunch and catkin "
        "overlays (the tutorial's launch files, some tests) will fail. Add the line '127.0.1.1 "
        "%s' to /etc/hosts, as Debian's installer writes it.\n" % (name, name)), result.stdout
    resolves = subprocess.run(['sh', '-c', 'getent hosts "$(hostname)"'],
                              capture_output=True).returncode == 0
    here = subprocess.run(['make', '--no-print-directory', '-C', WORKSPACE, 'host'],
                          capture_output=True, text=True, timeout=HANG_SECONDS)
    assert here.returncode == 0
    assert (here.stdout == '') == resolves, here.stdout
