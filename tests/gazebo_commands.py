"""gazebo_ros' command lines (gzserver, gazebo, roslaunch of its launch files, spawn_model) run
against a test's ROS graph: to completion, or started and waited for until /gazebo serves."""
import subprocess

from conftest import WORKSPACE
from onedof_harness.private_ros import COMMAND_TIMEOUT, wait_until


def output(result):
    return '%s\nstdout:\n%s\nstderr:\n%s' % (result.args, result.stdout, result.stderr)


def run(ros, *args, env=None, timeout=COMMAND_TIMEOUT):
    return subprocess.run(list(args), env=dict(ros.env, **(env or {})), cwd=WORKSPACE,
                          stdin=subprocess.DEVNULL, capture_output=True, text=True,
                          timeout=timeout)


def start_serving(ros, args, name, env=None):
    """Starts args and waits until /gazebo serves its last service."""
    proc = ros.start(args, name=name, env=env)
    wait_until(lambda: proc.poll() is not None or ros.has_service('/gazebo/unpause_physics'), 60,
               what='%s to serve /gazebo/unpause_physics' % ' '.join(args))
    assert proc.poll() is None, ros.log_text(proc)
    return proc
