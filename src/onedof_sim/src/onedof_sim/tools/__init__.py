"""Command-line tools beside the simulator node: plot (rqt_plot's syntax) and spawn_cli
(spawn_model's arguments and model sources)."""
import functools
import os

import rospkg


def package_path(package):
    """Where a ROS package of the workspace (or of the system) is."""
    return rospkg.RosPack().get_path(package)


def workspace_root():
    """The catkin workspace this package is built from (<workspace>/src/onedof_sim)."""
    return os.path.dirname(os.path.dirname(package_path('onedof_sim')))


def workspace_venv_bin():
    """bin/ of the workspace venv (make venv), where pybullet's python and py-spy live: rosrun
    runs the tools under the system python, which has neither."""
    return os.path.join(workspace_root(), '.venv', 'bin')


@functools.lru_cache(maxsize=None)
def package_executable(package, name):
    """The path of a package's executable, found as rosrun and roslaunch find it, once per
    process. A tool that starts an executable many times starts it by this path: rosrun's own
    lookup (two catkin_find processes) costs each start about 0.2 CPU-s."""
    import roslib.packages
    found = roslib.packages.find_node(package, name)
    if not found:
        raise RuntimeError('no executable %s in package %s: is the workspace built and its '
                           'devel/setup.bash sourced?' % (name, package))
    return found[0]


def rosrun_by_path(command):
    """`rosrun PACKAGE EXECUTABLE ARGS...` as the executable's path and ARGS (package_executable):
    the same process without rosrun's lookup; any other command as it is. Raises RuntimeError
    when the executable is not found."""
    if command[0] != 'rosrun':
        return list(command)
    _, package, name, *args = command
    return [package_executable(package, name)] + list(args)
