"""Command-line tools beside the simulator node: plot (rqt_plot's syntax) and spawn_cli
(spawn_model's arguments and model sources)."""
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
