"""Set-up output (issue 12 item 5): one line per step, saying what is installed or built and how
long it took; the full output in a log file; a failing step prints its own output in full. CMake's
"nosetests not found" and "GMock is not available" (true, and irrelevant here) stay in the log."""
import os
import re
import subprocess

from conftest import WORKSPACE

STEP = os.path.join(WORKSPACE, 'scripts', 'step')


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
        runs = [command for command in commands if tool in command]
        assert runs, tool
        for command in runs:
            assert 'scripts/step ' in command.split(tool)[0], command
