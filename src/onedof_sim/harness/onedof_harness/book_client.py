"""The book-shaped C++ client (tests/book_cpp_client), built as a student builds it: catkin_make of
the package in a scratch overlay on this workspace's devel. The tests and the benchmark both run
it from here."""
import fcntl
import os
import shutil
import subprocess

from onedof_harness.private_ros import BUILD_TIMEOUT
from onedof_sim.tools import workspace_root

PACKAGE = 'book_cpp_client'
# Its executables by control rate (Hz): the book's at 100 Hz, and the same source compiled for
# 1 kHz (CONTROL_RATE_HZ in its CMakeLists.txt).
EXECUTABLES = {100: 'book_controller', 1000: 'book_controller_1khz'}
NODE = '/book_controller'


def build_overlay(directory, packages=(PACKAGE,), timeout=BUILD_TIMEOUT):
    """catkin_make of packages (folders under the workspace's tests/, the client by default) in
    directory/overlay, under the workspace devel of this process's environment; returns the
    overlay's devel/setup.bash. Raises RuntimeError with the build's output when it fails; timeout
    (s) bounds a hung build."""
    overlay = os.path.join(str(directory), 'overlay')
    for package in packages:
        shutil.copytree(os.path.join(workspace_root(), 'tests', package),
                        os.path.join(overlay, 'src', os.path.basename(package)))
    env = dict(os.environ)
    env.pop('PYTHONPATH', None)  # as the Makefile builds: catkin_make sets its own
    # -C: catkin_make takes the workspace from $PWD (inherited: this workspace's), not the cwd.
    # Python3_EXECUTABLE: the ament-built CMake configs among Debian's ROS packages (pluginlib,
    # which image_transport's and nodelet's find) run their Python helpers with CMake's Python 3,
    # which must be Debian's, not another python3 on PATH.
    result = subprocess.run(['catkin_make', '-C', overlay, '-j2',
                             '-DPYTHON_EXECUTABLE=/usr/bin/python3',
                             '-DPython3_EXECUTABLE=/usr/bin/python3'],
                            cwd=overlay, env=dict(env, PWD=overlay), capture_output=True,
                            text=True, timeout=timeout)
    if result.returncode != 0:
        raise RuntimeError('catkin_make of %s failed:\n%s%s' % (
            ', '.join(packages), result.stdout[-3000:], result.stderr[-3000:]))
    return os.path.join(overlay, 'devel', 'setup.bash')


def shared_overlay(folder, packages=(PACKAGE,), timeout=BUILD_TIMEOUT):
    """build_overlay(folder, packages, timeout) done once for every process that asks with the
    same folder (an exclusive lock while it builds); returns the overlay's devel/setup.bash."""
    folder = str(folder)
    os.makedirs(folder, exist_ok=True)
    built = os.path.join(folder, 'built')
    with open(os.path.join(folder, 'build.lock'), 'w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not os.path.exists(built):
            # catkin_make writes setup.bash before it compiles: only this file says it succeeded.
            shutil.rmtree(os.path.join(folder, 'overlay'), ignore_errors=True)
            setup = build_overlay(folder, packages, timeout)
            with open(built, 'w') as f:
                f.write(setup)
        with open(built) as f:
            return f.read()


def command(setup, rate=100):
    """The command line running the client at `rate` Hz from the overlay whose setup.bash is
    `setup`."""
    return ['bash', '-c', 'source %s && exec rosrun %s %s' % (setup, PACKAGE, EXECUTABLES[rate])]
