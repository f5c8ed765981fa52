"""The physics engines of the simulator node. Their one list lives in the C++ core
(src/core/engines/registry.cpp), whose first entry is the default; the node prints it, and every
Python consumer reads it here.
"""
import functools
import subprocess

LIST_COMMAND = ('rosrun', 'onedof_sim', 'onedof_sim', '--list-physics')


@functools.lru_cache(maxsize=None)
def engine_names():
    """The engine names in registry order, the default first (as ~physics takes them). Needs the
    ROS environment of a built workspace (source devel/setup.bash)."""
    try:
        listed = subprocess.run(LIST_COMMAND, capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise RuntimeError('`%s` failed: %s (is the workspace built and devel/setup.bash '
                           'sourced?)' % (' '.join(LIST_COMMAND), error))
    names = tuple(listed.stdout.split())
    if listed.returncode != 0 or not names:
        raise RuntimeError('`%s` exited with %d and listed no engine: %s'
                           % (' '.join(LIST_COMMAND), listed.returncode,
                              (listed.stderr or listed.stdout).strip()[-500:]))
    return names


def default_engine():
    """The engine the node runs when none is named (the registry's first entry): launch files
    leave their physics argument empty for it, and the tools default to it by this name."""
    return engine_names()[0]


def node_command(engine):
    """The command that starts the simulator node on `engine`, as a user types it."""
    return ['rosrun', 'onedof_sim', 'onedof_sim', '_physics:=' + engine]
