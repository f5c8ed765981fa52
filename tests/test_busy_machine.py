"""busy_machine.py (make test-under-load): the spinners run beside the command, the exit status is
the command's, and no spinner outlives the run, whether the command fails, is interrupted or the
runner itself is killed."""
import os
import signal
import subprocess
import sys

from onedof_harness.private_ros import wait_until

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'busy_machine.py')


def children_of(pid):
    """{child pid: command name} of the processes whose parent is pid."""
    children = {}
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open('/proc/%s/stat' % entry) as f:
                stat = f.read()
        except OSError:
            continue
        name, fields = stat.split('(', 1)[1].rsplit(')', 1)
        if int(fields.split()[1]) == pid:
            children[int(entry)] = name
    return children


def child_names(pid):
    return children_of(pid).values()


def spinners_of(pid):
    """Pids of the children of pid but the command (`sleep`/`sh`)."""
    return [child for child, name in children_of(pid).items() if name not in ('sleep', 'sh')]


def alive(pid):
    try:
        with open('/proc/%d/stat' % pid) as f:
            return f.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except OSError:
        return False


def start(*args):
    return subprocess.Popen([sys.executable, SCRIPT] + list(args), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)


def test_the_exit_status_is_the_commands_and_the_spinners_ran_beside_it(tmp_path):
    # The command ends once this test has seen the spinners (it creates the file then).
    seen = tmp_path / 'spinners_seen'
    runner = start('--processes', '3', '--', 'sh', '-c',
                   'until [ -e %s ]; do sleep 0.05; done; exit 3' % seen)
    spinners = wait_until(lambda: len(spinners_of(runner.pid)) == 3 and spinners_of(runner.pid),
                          60, what='3 spinners')
    seen.touch()
    assert runner.wait(timeout=300) == 3, runner.stdout.read()
    assert not any(alive(pid) for pid in spinners)


def test_ctrl_c_stops_the_command_and_the_spinners():
    # SIGINT as a terminal's foreground job has it: a suite started in the background by a
    # non-interactive shell inherits SIGINT ignored, and so would the runner and its command.
    runner = subprocess.Popen([sys.executable, SCRIPT, '--processes', '2', '--', 'sleep', '60'],
                              start_new_session=True, stdout=subprocess.PIPE, text=True,
                              preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert runner.stdout.readline().startswith('busy_machine: 2 CPU spinners beside: sleep 60')
    spinners = wait_until(lambda: len(spinners_of(runner.pid)) == 2 and spinners_of(runner.pid),
                          30, what='2 spinners')
    wait_until(lambda: any(name == 'sleep' for name in child_names(runner.pid)), 30,
               what='the command to start')
    os.killpg(runner.pid, signal.SIGINT)  # what the terminal does on Ctrl-C
    out, _ = runner.communicate(timeout=30)
    assert out == 'busy_machine: spinners stopped; the command exited with %d\n' % (
        128 + signal.SIGINT)
    assert runner.returncode == 128 + signal.SIGINT
    wait_until(lambda: not any(alive(pid) for pid in spinners), 60, what='the spinners to stop')


def test_spinners_stop_by_themselves_when_the_runner_is_killed():
    runner = start('--processes', '2', '--', 'sleep', '10')
    spinners = wait_until(lambda: len(spinners_of(runner.pid)) == 2 and spinners_of(runner.pid),
                          30, what='2 spinners')
    runner.kill()
    runner.wait()
    wait_until(lambda: not any(alive(pid) for pid in spinners), 60, what='the spinners to stop')


def test_spinners_stop_after_max_seconds_while_the_command_runs_on():
    runner = start('--processes', '1', '--max-seconds', '1', '--', 'sleep', '3600')
    spinner = wait_until(lambda: spinners_of(runner.pid), 60, what='a spinner')[0]
    command = wait_until(lambda: [child for child, name in children_of(runner.pid).items()
                                  if name == 'sleep'], 60, what='the command to start')[0]
    wait_until(lambda: not alive(spinner), 120, what='the spinner to stop by itself')
    # It stopped on its own: the command still runs, and the runner waits for it.
    assert alive(command) and runner.poll() is None
    runner.terminate()  # passed on to the command
    assert runner.wait(timeout=300) == 128 + signal.SIGTERM
    assert not alive(command)
