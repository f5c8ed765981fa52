"""The physics engines of the simulator node. Their one list lives in the C++ core
(src/core/engines/registry.cpp), whose first entry is the default; the node prints it, and every
Python consumer reads it here.
"""
import functools
import subprocess

from onedof_sim.tools import package_executable


@functools.lru_cache(maxsize=None)
def engine_names():
    """The engine names in registry order, the default first (as ~physics takes them). Needs the
    ROS environment of a built workspace (source devel/setup.bash). Every tool asks at its start:
    the node is run by its path, without rosrun's lookup (about 0.2 CPU-s)."""
    command = [package_executable('onedof_sim', 'onedof_sim'), '--list-physics']
    try:
        listed = subprocess.run(command, capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise RuntimeError('`%s` failed: %s (is the workspace built and devel/setup.bash '
                           'sourced?)' % (' '.join(command), error))
    names = tuple(listed.stdout.split())
    if listed.returncode != 0 or not names:
        raise RuntimeError('`%s` exited with %d and listed no engine: %s'
                           % (' '.join(command), listed.returncode,
                              (listed.stderr or listed.stdout).strip()[-500:]))
    return names


def default_engine():
    """The engine the node runs when none is named (the registry's first entry): launch files
    leave their physics argument empty for it, and the tools default to it by this name."""
    return engine_names()[0]


def node_command(engine):
    """The command that starts the simulator node on `engine`, as a user types it."""
    return ['rosrun', 'onedof_sim', 'onedof_sim', '_physics:=' + engine]
